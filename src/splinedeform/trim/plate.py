"""Kirchhoff plate on a trimmed square, in the WEB-spline basis.

With ``d = W Σ_k (E S c)_k b_k`` (:mod:`splinedeform.trim.web`, ``W = w^p`` from
:mod:`splinedeform.trim.weight`) the plate energy and mass

.. math:: a(d, d) = D ∫_Ω d_{xx}^2 + d_{yy}^2 + 2ν d_{xx} d_{yy} + 2(1-ν) d_{xy}^2,
          \\qquad m(d, d) = ρh ∫_Ω d^2

are assembled with :func:`splinedeform.trim.quadrature.trim_quadrature`. ``ν = 0`` is the
project's plate weights ``w20 = w11 = w02 = D`` (``d_xx² + 2 d_xy² + d_yy²``,
docs/model.md); for a clamped edge the ``ν`` term integrates to zero and any ``ν`` gives
the same deflection. Derivatives of ``Φ = W b`` by the product rule, e.g.
``Φ_xy = W_xy b + W_x b_y + W_y b_x + W b_xy``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray

from ..basis import BSplineBasis
from ..errors import InputError
from .cells import Grid
from .loops import PolygonLoop, TrimDomain
from .quadrature import TrimQuadrature, trim_quadrature
from .values import tensor_values
from .web import WebBasis, normalisation, web_basis
from .weight import DiscWeight, RvachevWeight


@dataclass(frozen=True)
class TrimmedPlate:
    """Reduced matrices ``K_r = Tᵀ K T``, ``M_r = Tᵀ M T`` and load ``F_r = Tᵀ F``
    with ``T = E S`` the WEB map (all B-spline coefficients from WEB coefficients)."""

    stiffness: sp.csr_matrix
    mass: sp.csr_matrix
    load: NDArray[np.float64]
    web_map: sp.csr_matrix
    web: WebBasis
    bases: tuple[BSplineBasis, BSplineBasis]
    weight: DiscWeight | RvachevWeight

    def deflection(self, coefficients: NDArray[np.float64], p: NDArray[np.float64]
                   ) -> NDArray[np.float64]:
        """``d(p) = W(p) Σ_k (T c)_k b_k(p)`` at points ``(P, 2)``."""
        rows = _values(self.bases, p)[0]
        return self.weight(p) * (rows @ (self.web_map @ coefficients))


def _values(bases: tuple[BSplineBasis, BSplineBasis], p: NDArray[np.float64]
            ) -> list[sp.csr_matrix]:
    """Sparse ``b, b_x, b_y, b_xx, b_xy, b_yy`` of the tensor B-splines at ``p`` (rows)."""
    orders = ((0, 0), (1, 0), (0, 1), (2, 0), (1, 1), (0, 2))
    table = tensor_values(bases, p, orders)
    return [table[o] for o in orders]


def assemble_plate(domain: TrimDomain, cells: int, degree: int,
                   weight: DiscWeight | RvachevWeight,
                   rigidity: float = 1.0, poisson: float = 0.0, density: float = 1.0,
                   pressure: float = 1.0, order: int | None = None,
                   extended: bool = True) -> TrimmedPlate:
    """Kirchhoff plate over ``Ω ⊂ [0, 1]²`` on a ``cells × cells`` grid of the unit square
    in degree-``degree`` WEB-splines (uniform, Höllig, knots).

    ``extended=False`` keeps every B-spline whose support meets ``Ω`` instead, each times
    ``W`` and without extension: the plain weighted basis, whose matrices degenerate as a
    trim loop leaves a B-spline a sliver of its support (kept for comparison).
    """
    if degree < 2:
        raise InputError(f"a plate needs B-splines of degree >= 2, got {degree}")
    if isinstance(weight, RvachevWeight) and any(
            isinstance(loop, PolygonLoop) for loop in weight.domain.loops):
        raise InputError("the R-function weight of a polygon has second derivatives growing "
                         "like 1/r at its corners, so the plate energy of w·B is infinite "
                         "there; a plate needs circle loops (or a smooth weight) for now")
    if not -1.0 < poisson < 0.5:
        raise InputError(f"Poisson's ratio must lie in (-1, 0.5), got {poisson!r}")
    grid = Grid((cells, cells))
    bases = (BSplineBasis(degree, cells, 1.0, "uniform"), BSplineBasis(degree, cells, 1.0, "uniform"))
    q = degree + 2 * weight.power + 2 if order is None else order
    quad: TrimQuadrature = trim_quadrature(domain, grid, q)
    web = web_basis(quad.classes, degree)
    centres = (np.argwhere(np.ones(quad.classes.shape, bool)) + 0.5) * np.array(grid.h)
    scale = normalisation(quad.classes, degree, weight(centres).reshape(quad.classes.shape),
                          web.inner)
    T = (web.extension @ sp.diags(scale)).tocsr()
    if not extended:
        kept = np.flatnonzero((web.inner | web.outer).ravel())
        T = sp.csr_matrix((np.ones(kept.size), (kept, np.arange(kept.size))),
                          shape=(web.inner.size, kept.size))
    p = np.clip(quad.points, 0.0, 1.0)
    b, bx, by, bxx, bxy, byy = _values(bases, p)
    W, Wx, Wy, Wxx, Wxy, Wyy = (sp.diags(f) for f in weight.derivatives(p))
    phi = W @ b
    phi_xx = Wxx @ b + 2 * Wx @ bx + W @ bxx
    phi_yy = Wyy @ b + 2 * Wy @ by + W @ byy
    phi_xy = Wxy @ b + Wx @ by + Wy @ bx + W @ bxy
    om = sp.diags(quad.weights)
    K = rigidity * (phi_xx.T @ om @ phi_xx + phi_yy.T @ om @ phi_yy
                    + poisson * (phi_xx.T @ om @ phi_yy + phi_yy.T @ om @ phi_xx)
                    + 2 * (1 - poisson) * phi_xy.T @ om @ phi_xy)
    M = density * (phi.T @ om @ phi)
    F = pressure * (phi.T @ quad.weights)
    Kr, Mr = (T.T @ K @ T).tocsr(), (T.T @ M @ T).tocsr()
    return TrimmedPlate(((Kr + Kr.T) * 0.5).tocsr(), ((Mr + Mr.T) * 0.5).tocsr(), T.T @ F,
                        T, web, bases, weight)
