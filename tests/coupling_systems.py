"""Small bodies of flat patches for the coupling tests: patches, loads, a static solve.

Each patch of the unit square is drawn with its control points at the Greville abscissae
(linear precision), so its parameters are lengths and the parametric energy is the
physical one. Stiffnesses are the per-patch ``Model(...).K_full`` (block diagonal), the
boundary the per-patch constraint maps; the coupling matrices are added before reduction.
"""

from __future__ import annotations

from typing import Callable, Sequence

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from splinedeform import Material, Model
from splinedeform.assembly import full_matrices
from splinedeform.basis import BSplineBasis
from splinedeform.boundary import build_constraints
from splinedeform.knots import KnotVectorBasis
from splinedeform.quadrature import gauss_points, gram_matrix
from splinedeform.surface import Surface

MEMBRANE = Material(w10=1.0, w01=1.0)
PLATE = Material(w20=1.0, w11=1.0, w02=1.0)      # Hessian energy: ∫ (Δw)² for clamped edges
CLAMPED_PLATE_CENTRE = 0.00126532
"""Centre deflection ``w / (q a⁴ / D)`` of the clamped square Kirchhoff plate (Timoshenko &
Woinowsky-Krieger, Table 35: 0.00126)."""


def flat_patch(x0: float, length: float, cells_u: int, cells_v: int, degree: int = 3,
               basis_u: object | None = None) -> Surface:
    """``[x0, x0 + length] × [0, 1]`` in the plane z = 0, open knots (or ``basis_u``)."""
    bu = basis_u or BSplineBasis(degree, cells_u, length, "open")
    bv = BSplineBasis(degree, cells_v, 1.0, "open")
    gu, gv = bu.greville(), bv.greville()
    P = np.stack(np.broadcast_arrays(x0 + gu[:, None], gv[None, :], 0.0 * gu[:, None]), -1)
    return Surface(P, bu, bv)


def c0_basis(degree: int, cells: int, repeats: int | None = None) -> KnotVectorBasis:
    """Open knots on ``[0, 1]``, ``cells`` equal spans, ``u = 1/2`` repeated ``repeats`` times
    (default ``degree``: a C0 line)."""
    inner = np.arange(1, cells) / cells
    inner = np.concatenate([inner[inner != 0.5], np.full(repeats or degree, 0.5)])
    return KnotVectorBasis(degree, np.sort(np.concatenate([np.zeros(degree + 1), inner,
                                                           np.ones(degree + 1)])))


def c1_basis(degree: int, cells: int) -> KnotVectorBasis:
    """:func:`c0_basis` with ``u = 1/2`` repeated ``degree − 1`` times: ``C^1`` there."""
    return c0_basis(degree, cells, degree - 1)


def load_vector(surface: Surface, x0: float, f: Callable[[np.ndarray], np.ndarray]
                ) -> np.ndarray:
    """``F_kl = ∫∫ f(x) b_k b_l`` for a load depending on ``x = x0 + u`` only (Gauss, n + 2 points).

    Exact for a piecewise-constant ``f`` whose jumps lie on knots.
    """
    (xu, wu), (xv, wv) = (gauss_points(b, b.degree + 2) for b in (surface.basis_u,
                                                                  surface.basis_v))
    Bu, Bv = surface.basis_u.matrix(xu), surface.basis_v.matrix(xv)
    return np.outer(Bu.T @ (wu * f(x0 + xu)), Bv.T @ wv).ravel()


def uniform(x: np.ndarray) -> np.ndarray:
    return np.ones_like(x)


def left_half(x: np.ndarray) -> np.ndarray:
    """Unit load on ``x < 1/2`` only: the interface at ``x = 1/2`` carries the flux."""
    return (x < 0.5).astype(float)


def stiffness_of(surface: Surface, material: Material, boundary: object
                 ) -> tuple[sp.csr_matrix, sp.csr_matrix]:
    """``(K_full, T)`` of one patch; a C0 basis (which Model refuses for bending) is assembled
    from its broken Gram matrices, the per-span integrals of the second derivatives."""
    if getattr(surface.basis_u, "continuity", 1) >= 1:
        model = Model(surface, material, boundary=boundary)
        return model.K_full, model.constraints.T
    grams = [[gram_matrix(b, a) for a in range(3)] for b in (surface.basis_u, surface.basis_v)]
    K, _ = full_matrices(grams[0], grams[1], material)
    return K, build_constraints(surface.basis_u, surface.basis_v, boundary).T


def offsets(patches: Sequence[Surface]) -> list[int]:
    return list(np.cumsum([0] + [s.shape[0] * s.shape[1] for s in patches[:-1]]))


def solve(patches: Sequence[Surface], starts: Sequence[float], boundaries: Sequence[object],
          material: Material, coupling: sp.spmatrix | float,
          f: Callable[[np.ndarray], np.ndarray] = uniform) -> list[np.ndarray]:
    """Static displacements (one scalar coordinate) of each patch's control points."""
    parts = [stiffness_of(s, material, b) for s, b in zip(patches, boundaries)]
    K = sp.block_diag([k for k, _ in parts]).tocsr() + coupling
    T = sp.block_diag([t for _, t in parts]).tocsr()
    F = np.concatenate([load_vector(s, x0, f) for s, x0 in zip(patches, starts)])
    d = T @ spla.spsolve((T.T @ K @ T).tocsc(), T.T @ F)
    return np.split(d, offsets(patches)[1:])


def value(surface: Surface, d: np.ndarray, u: float, v: float) -> float:
    return float((surface.evaluation_matrix(u, v) @ d)[0])


def single(cells: int, material: Material, edge: str, f: Callable = uniform, degree: int = 3
           ) -> float:
    """Centre deflection of the unit square as one patch, ``cells × cells`` spans."""
    s = flat_patch(0.0, 1.0, cells, cells, degree)
    return value(s, solve([s], [0.0], [edge], material, 0.0, f)[0], 0.5, 0.5)


def slope_jump(surface: Surface, net: np.ndarray) -> float:
    """``max |∂_u d(1/2⁺) − ∂_u d(1/2⁻)|`` along u = 1/2 over the largest ``|∂_u d|``."""
    v = np.linspace(0.0, 1.0, 41)
    below = surface.derivative(0.5 - 1e-12, v, 1, 0, net)      # the left span's last point
    above = surface.derivative(0.5, v, 1, 0, net)
    x = np.linspace(0.0, 1.0, 81)
    slopes = surface.derivative(x[:, None], x[None, :], 1, 0, net)
    return float(np.abs(above - below).max() / np.abs(slopes).max())
