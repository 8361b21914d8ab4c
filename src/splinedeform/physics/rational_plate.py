"""The thin plate under tension on a NURBS patch whose weights are not a product.

With weights ``w_ij`` that do not factor as ``a_i b_j`` the rational basis
``R_ij = w_ij N_i(u) N_j(v) / W``, ``W = Σ_kl w_kl N_k(u) N_l(v)``, is not a tensor
product, and the Kronecker form of :mod:`splinedeform.assembly` does not apply. The same
energy (DESIGN.md §1.5)

.. math:: K_{kl} = \\iint w_{10} ∂_u R_k ∂_u R_l + w_{01} ∂_v R_k ∂_v R_l
          + w_{20} ∂_{uu} R_k ∂_{uu} R_l + 2 w_{11} ∂_{uv} R_k ∂_{uv} R_l
          + w_{02} ∂_{vv} R_k ∂_{vv} R_l \\, du\\, dv, \\qquad
          M_{kl} = μ \\iint R_k R_l \\, du\\, dv

is assembled element by element instead: on every knot span pair, at a tensor Gauss grid,
the derivatives of ``R`` follow from the quotient rule on ``A_k = w_k N_k = R_k W``:

.. math:: R_u = (A_u - R W_u) / W, \\quad R_{uu} = (A_{uu} - 2 R_u W_u - R W_{uu}) / W,
          \\quad R_{uv} = (A_{uv} - R_u W_v - R_v W_u - R W_{uv}) / W

(and likewise in ``v``). ``R`` is not a polynomial, so the rule is not exact: ``2n + 10``
points per span and direction, as :class:`~splinedeform.knots.RationalBasis` uses. Measured
on random weights in ``[0.5, 2]`` (a factor 4 between neighbours), the energy of a random
field is off by 3e-6 with 12 points, 1e-8 with 16, 1e-13 with 24
(``tests/test_rational_plate.py``); CAD weights, close to 1, do much better.

Used by :func:`splinedeform.assembly.patch_matrices` for a surface with
:attr:`~splinedeform.Surface.net_weights` (the parametric physics of
:class:`~splinedeform.Model` and of a body).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray

from ..knots import KnotVectorBasis
from ..material import Material
from ..quadrature import gauss_points
from ..rational import basis_derivatives, check_weights
from .metric import ORDERS
from .shell import by_cell
from .shell_assembly import Pattern, assemble_cells

Array = NDArray[np.float64]


def rational_derivatives(basis_u: KnotVectorBasis, basis_v: KnotVectorBasis,
                         weights: Array, u: Array, v: Array
                         ) -> tuple[NDArray[np.int64], dict[tuple[int, int], Array]]:
    """``D^p_u D^q_v R_k`` of the non-zero functions on the grid ``u × v``.

    Returns the flat index ``i n_v + j`` of each local function, ``(Qu, Qv, pu pv)``, and
    ``{(p, q): (Qu, Qv, pu pv)}`` for ``p + q <= 2`` (see the module docstring), from
    :func:`splinedeform.rational.basis_derivatives`.
    """
    w = check_weights(weights, (basis_u.size, basis_v.size), "general NURBS weights")
    iu, Bu = basis_u.nonzero_derivatives(u, 2)                  # (3, Qu, pu)
    iv, Bv = basis_v.nonzero_derivatives(v, 2)
    index, R = basis_derivatives(iu[:, None], Bu[:, :, None], iv[None], Bv[:, None], w,
                                 ORDERS)
    return index, {k: R[k] for k in ORDERS}


def matrices(basis_u: KnotVectorBasis, basis_v: KnotVectorBasis, weights: Array,
             material: Material, points_per_cell: int | None = None
             ) -> tuple[sp.csr_matrix, sp.csr_matrix]:
    """Stiffness ``K`` and consistent mass ``M`` (see the module docstring), each
    ``(n_u n_v)²`` over the flat net ``i n_v + j``, shared by x, y and z.

    Cell by cell, a bounded number of cell rows at a time: each cell's block is ``BᵀB`` for
    the rows ``B = [√(c_t a_q) ∂_t R]`` of its points ``q`` and terms ``t`` stacked (the
    weights ``c_t >= 0`` of the material), scattered into a precomputed sparse pattern
    (:mod:`.shell_assembly`), as the intrinsic physics does.
    """
    w = check_weights(weights, (basis_u.size, basis_v.size), "general NURBS weights")
    qu = points_per_cell or 2 * basis_u.degree + 10
    qv = points_per_cell or 2 * basis_v.degree + 10
    u, au = gauss_points(basis_u, qu)
    v, av = gauss_points(basis_v, qv)
    iu, Bu = basis_u.nonzero_derivatives(u, 2)                  # (3, Qu, pu)
    iv, Bv = basis_v.nonzero_derivatives(v, 2)
    cells_u, cells_v = iu[::qu], iv[::qv]
    pattern = Pattern.of(cells_u, cells_v, basis_u.size, basis_v.size, 1)
    terms = [(factor, order) for factor, order in
             ((material.w10, (1, 0)), (material.w01, (0, 1)), (material.w20, (2, 0)),
              (2 * material.w11, (1, 1)), (material.w02, (0, 2))) if factor]

    def shapes(rows: slice, orders: tuple = ORDERS
               ) -> tuple[dict[tuple[int, int], Array], Array]:
        p = slice(rows.start * qu, rows.stop * qu)
        _, R = basis_derivatives(iu[p][:, None], Bu[:, p][:, :, None], iv[None], Bv[:, None],
                                 w, orders)
        return R, au[p][:, None] * av[None, :]

    def stiffness(rows: slice) -> Array:
        R, dA = shapes(rows)
        k = R[0, 0].shape[-1]
        if not terms:
            return np.zeros((rows.stop - rows.start, cells_v.shape[0], k, k))
        B = np.stack([np.sqrt(factor * dA)[..., None] * R[order] for factor, order in terms],
                     axis=2)                                            # (Qa, Qv, t, k)
        B = by_cell(B, (qu, qv))
        B = B.reshape(B.shape[:2] + (-1, k))
        return np.swapaxes(B, -1, -2) @ B

    def mass(rows: slice) -> Array:
        R, dA = shapes(rows, ((0, 0),))
        N0 = by_cell(R[0, 0], (qu, qv))                                 # (A, B, q, k)
        return np.swapaxes(N0, -1, -2) @ (by_cell(material.mass * dA, (qu, qv))[..., None] * N0)

    return (assemble_cells(pattern, cells_u, cells_v, stiffness),
            assemble_cells(pattern, cells_u, cells_v, mass))
