"""The intrinsic plate (``physics = "intrinsic"``, :mod:`splinedeform.physics.intrinsic`) on
a trimmed region: its energy over the trimmed cells, Nitsche's terms on held loops.

Per coordinate ``E(d) = ½ ∫_Ω T g^αβ d_,α d_,β + D (Δ_S d)² dA`` with the Laplace–Beltrami
operator ``Δ_S d = g^αβ d_,αβ + b^γ d_,γ``, ``b^γ = −g^αβ Γ^γ_αβ``, and ``dA = √g du dv``:
in the strain rows of :mod:`.energy_forms`, ``e = (d_,u, d_,v, Δ_S d)`` with
``C = √g diag(T g^αβ, D)``. Its matrices use the trimmed quadrature of the parametric
plate (:func:`.model_matrices.quadrature_of`), the same Höllig extension as constraint map
and Nitsche's symmetric terms from the energy integrated by parts in ``(u, v)``
(:func:`.energy_forms.nitsche_matrix`): a clamped loop holds ``d`` and its gradient, a
pinned one ``d`` (the moment ``D Δ_S d`` natural). On a flat unit-speed parametrisation
the tension and mass terms are the parametric plate's with ``w10 = w01 = T``; the bending
term ``(Δ d)²`` differs from ``d_uu² + 2 d_uv² + d_vv²`` by a null Lagrangian, so a
pinned loop is the plate with ``ν = 1`` (``Δd = 0`` on it).
"""

from __future__ import annotations

from typing import Any, Mapping

import numpy as np
import scipy.sparse as sp

from ..material import Material
from ..physics.intrinsic import coefficients
from .energy_forms import Array, Form, Geometry, gradient_rotation
from .model_matrices import form_matrices


def intrinsic_form(material: Material) -> Form:
    """The intrinsic plate's :class:`~.energy_forms.Form` (module docstring)."""
    T, D = coefficients(material)

    def strains(geo: Geometry) -> tuple[Array, Array]:
        P = len(geo.sqrt_g)
        gi, gamma = geo.g_inv, geo.gamma
        V = np.zeros((P, 3, 1, 5))
        V[:, 0, 0, 0] = V[:, 1, 0, 1] = 1.0
        b = -(gi[:, None, 0, 0] * gamma[:, :, 0] + 2 * gi[:, None, 0, 1] * gamma[:, :, 1]
              + gi[:, None, 1, 1] * gamma[:, :, 2])                       # b^γ, (P, 2)
        V[:, 2, 0] = np.column_stack([b, gi[:, 0, 0], 2 * gi[:, 0, 1], gi[:, 1, 1]])
        C = np.zeros((P, 3, 3))
        C[:, :2, :2] = T * geo.sqrt_g[:, None, None] * gi
        C[:, 2, 2] = D * geo.sqrt_g
        return V, C

    return Form(1, strains, gradient_rotation, material.mass)


def intrinsic_matrices(surface: Any, material: Material,
                       held: Mapping[int, str | tuple[str, ...]]
                       ) -> tuple[sp.csr_matrix, sp.csr_matrix]:
    """``K`` (with Nitsche's terms of the ``held`` loops) and ``M`` over the region."""
    return form_matrices(surface, intrinsic_form(material), held)
