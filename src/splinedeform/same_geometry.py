"""A model of another material on the same geometry: the parts that do not depend on it shared.

``K_r = Σ w_ab (T_uᵀ G_a^u T_u) ⊗ (T_vᵀ G_b^v T_v)`` and
``M_r = μ (T_uᵀ G_0^u T_u) ⊗ (T_vᵀ G_0^v T_v)`` (DESIGN.md §1.5, :mod:`splinedeform.model`):
the material enters only through the weights. A model with these Kronecker factors
(:class:`~splinedeform.assembly.ReducedFactors`) shares its surface, constraints, reduced
1-D Gram matrices and the layouts of their sums with the new one, whose own assembly is
the weighted sums; any other (trimmed, intrinsic, rational weights, coupled C0 lines,
fixed points that leave no rectangle) is built anew.
"""

from __future__ import annotations

import time
from dataclasses import replace

from .assembly import check_bending, reduced_matrices
from .errors import InputError
from .material import Material
from .model import Model
from .physics.coupling_model import c0_coupling
from .static_solve import check_options


def with_material(model: Model, material: Material) -> Model:
    """``model``'s surface, boundary, mass matrix and physics with ``material``."""
    start = time.perf_counter()
    surface = model.surface
    if model._arguments is None:
        raise InputError(f"with_material applies to a Model of one patch, not to a "
                         f"{type(model).__name__}: build it with the new material")
    if model._factors is None or c0_coupling(surface, material,
                                             model.constraints.edges) is not None:
        return Model(surface, material, mass_matrix=model.mass_matrix, rest=model.rest,
                     physics=model.physics, **model._arguments)
    check_options(material, model.mass_matrix, model.rest, model.physics)
    check_bending(surface, material)
    new = Model.__new__(Model)
    new.surface, new.material = surface, material
    new.mass_matrix, new.rest, new.physics = model.mass_matrix, model.rest, model.physics
    new.constraints, new.gram_u, new.gram_v = model.constraints, model.gram_u, model.gram_v
    new._factors, new._arguments, new._full = model._factors, model._arguments, None
    new.formulation = replace(model.formulation, material=material)
    reduced = reduced_matrices(model.gram_u, model.gram_v, material,
                               model.mass_matrix == "lumped", model.constraints,
                               model._factors)
    assert reduced is not None                  # the factors are those of T_u and T_v
    new._K, new._M, new._C = reduced
    new._finish(start)
    return new
