"""The thin plate under tension as a :class:`~.formulation.Formulation`.

One unknown per control point, shared by x, y and z (DESIGN.md §1.5): the free state is
``(n_free, 3)`` and every coordinate has the same ``K_r``, ``M_r`` and

.. math:: C_r = (γ/μ) M_r + β K_r.

The energy is measured in the parameters (``parametric``, Kronecker Gram matrices,
:mod:`splinedeform.assembly`) or on the initial surface (``intrinsic``, :mod:`.intrinsic`);
which one, and the constraint map of a surface or a body, are decided by the model's
constructors (:class:`splinedeform.Model`, :class:`splinedeform.BodyModel`). Rigid modes
are counted from the weights and the constraints (:mod:`splinedeform.spectrum`), so
:attr:`rigid_basis` is ``None``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable, Mapping

import numpy as np
import scipy.sparse as sp
from numpy.typing import ArrayLike, NDArray

from ..assembly import (ReducedFactors, full_matrices, gram_matrices, masked_matrices,
                        patch_matrices, reduced_factors, reduced_matrices)
from ..body.loads import surface_field
from ..boundary import Constraints, build_constraints
from ..errors import InputError, SingularSystemError
from ..material import Material
from ..readout import BodyReadout, Readout
from ..solvers.system import Reduction
from ..static_solve import solve_stiffness
from ..surface import Surface
from ..trim.model_matrices import trimmed_system
from . import intrinsic
from .coupling_model import bends, c0_coupling
from .coupling_ties import tie_c0_lines

Array = NDArray[np.float64]
METHODS = ("analytic", "newmark", "radau3", "radau5", "radau7", "genalpha", "rk45", "dop853",
           "radau", "bdf")


@dataclass
class PlateFormulation:
    """The plate of one surface (``surface``) or of a body's patches (``patches``).

    ``reduction_type`` makes the load vectors (a body's
    :class:`~splinedeform.physics.plate_body.BodyReduction` reads its patches one after another).
    """

    physics: str
    material: Material
    surface: Any = None
    patches: tuple | None = None
    reduction_type: Callable[..., Reduction] = Reduction
    unconstrained: bool = False
    edges: Any = None

    per_point = 1
    unknowns_label = "free control points"
    methods = METHODS
    rigid_basis = None

    @property
    def damping_rate(self) -> float:
        """``γ/μ``."""
        return self.material.damping / self.material.mass

    @property
    def rayleigh(self) -> float:
        """``β``."""
        return self.material.rayleigh

    def reduction(self, T: sp.spmatrix, rest: Array | None) -> Reduction:
        if self.patches is None and self.reduction_type is Reduction:
            return SurfaceReduction(T, self.surface, rest)
        return self.reduction_type(T, self.surface if self.patches is None else self.patches,
                                   rest)

    def static_displacement(self, model: Any, F: Array) -> Array:
        """The band Cholesky of :func:`splinedeform.static_solve.solve_stiffness`, after
        refusing a surface that nothing holds (its translations cost no energy)."""
        if self.unconstrained:
            raise SingularSystemError(
                "static solve of an unconstrained surface: every edge is free and no control "
                "point is fixed, so rigid translations cost no energy and K is singular. "
                "Fix an edge (boundary='clamped' or e.g. {'u0': 'pinned'}) or some control "
                "points (fixed=mask)")
        return solve_stiffness(model, F)

    def eigen_options(self, K_r: sp.spmatrix, check_spectrum: bool) -> dict[str, Any]:
        """The condition-number guard (:func:`~splinedeform.solvers.rigid.check_resolved`),
        or none; the advice is the model's (:func:`splinedeform.spectrum.eigen_advice`)."""
        return {"guard": "condition" if check_spectrum else "off"}

    def readout(self, T: sp.spmatrix, M_r: sp.spmatrix, K_r: sp.spmatrix) -> Any:
        if self.patches is None:
            return Readout(self.surface, T, M_r, K_r)
        return BodyReadout(self.patches, T, M_r, K_r)


@dataclass(frozen=True)
class SurfaceReduction(Reduction):
    """The :class:`~splinedeform.solvers.system.Reduction` of one surface, a pressure along
    its :attr:`~splinedeform.Surface.orientation` (:func:`~splinedeform.body.loads.surface_field`)."""

    def field(self, term: Any, t: float = 0.0) -> Array:
        return surface_field(term, self.surface, t)


@dataclass(frozen=True)
class PlateSystem:
    """The plate of one surface, assembled: its formulation, constraint map, the 1-D Gram
    factors (``None`` where the matrices are no Kronecker products), ``(K, M)`` of the
    whole net where assembled (else ``None``: made from the Gram factors when asked),
    ``(K_r, M_r, C_r)`` (``C_r`` None: from the formulation), a trimmed net's rigid
    mode count (else ``None``) and the reduced 1-D Gram factors that a model of another
    material shares (``None`` where ``K_r`` is not made from them)."""

    formulation: PlateFormulation
    constraints: Constraints
    gram_u: Any
    gram_v: Any
    full: tuple[sp.csr_matrix, sp.csr_matrix] | None
    reduced: tuple[sp.csc_matrix, sp.csc_matrix, sp.csc_matrix | None]
    rigid_modes: int | None
    factors: ReducedFactors | None = None


def surface_system(surface: Surface, material: Material, boundary: str | Mapping[str, str],
                   fixed: ArrayLike | None, mass_matrix: str, physics: str, rest: str
                   ) -> PlateSystem:
    """Assemble the plate of :class:`splinedeform.Model` on one surface.

    ``parametric`` with weights that factor: ``K_r``, ``M_r`` from the reduced Kronecker
    factors (:func:`~splinedeform.assembly.reduced_matrices`) and ``C_r`` with them, or
    their principal submatrices where fixed points leave no rectangle free
    (:func:`~splinedeform.assembly.masked_matrices`); otherwise ``K_r = Tᵀ K T``,
    ``M_r = Tᵀ M T`` of the matrices of the whole net (``intrinsic``, :mod:`.intrinsic`; a
    trimmed region, :mod:`splinedeform.trim.model_matrices`; general NURBS weights), plus
    the penalty tying the slopes across each C0 knot line (:mod:`.coupling_model`).
    """
    lumped = mass_matrix == "lumped"
    trimmed = None if surface.trim is None else trimmed_system(
        surface, material, boundary, lumped, physics, fixed, rest)
    constraints = trimmed.constraints if trimmed else build_constraints(
        surface.basis_u, surface.basis_v, boundary,
        None if fixed is None else np.asarray(fixed), surface.control_points)
    if constraints.n_free == 0:
        error = InputError(
            f"no free coordinate: the boundary {constraints.edges} fixes every one of "
            f"the {surface.shape[0]} x {surface.shape[1]} control points (cells "
            f"{surface.basis_u.cells} x {surface.basis_v.cells}, degree "
            f"{surface.basis_u.degree}), so nothing can move; free an edge, or use more cells "
            "(surface.cells; a CAD or control net surface: insert knots with surface.refine)")
        error.key = "boundary"  # type: ignore[attr-defined]
        raise error
    formulation = PlateFormulation(physics, material, surface,
                                   unconstrained=constraints.unconstrained)
    general = surface.net_weights is not None         # weights that do not factor
    gram_u, gram_v = (None, None) if general else gram_matrices(surface)
    full = ((trimmed.stiffness, trimmed.mass) if trimmed
            else intrinsic.matrices(surface, material, lumped) if physics == "intrinsic"
            else patch_matrices(surface, material, physics, lumped)[2:] if general else None)
    tied: set[tuple[str, float]] = set()
    if not trimmed and bends(material):    # smooth C0 lines: C1 in the constraint map
        constraints, tied = tie_c0_lines(surface, constraints)
    kinks = c0_coupling(surface, material, constraints.edges, exact=tied)
    if kinks is not None or tied:          # the slopes tied across each C0 line
        K, M = full if full is not None else full_matrices(gram_u, gram_v, material, lumped)
        K = K if kinks is None else K + kinks
        full, gram_u, gram_v = (K.tocsr(), M), None, None
    factors = None if full is not None else reduced_factors(gram_u, gram_v, constraints)
    reduced = None if factors is None else reduced_matrices(gram_u, gram_v, material, lumped,
                                                            constraints, factors)
    if reduced is None and full is None:   # fixed points that leave no rectangle free
        reduced = masked_matrices(gram_u, gram_v, material, lumped, constraints)
    if reduced is None:                    # Tᵀ K T of the whole net's matrices
        if full is None:
            full = full_matrices(gram_u, gram_v, material, lumped)
        T = constraints.T
        reduced = ((T.T @ full[0] @ T).tocsc(), (T.T @ full[1] @ T).tocsc(), None)
    return PlateSystem(formulation, constraints, gram_u, gram_v, full, reduced,
                       trimmed.rigid_modes if trimmed else None, factors)
