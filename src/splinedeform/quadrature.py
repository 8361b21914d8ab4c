"""Exact one-dimensional Gram matrices of a B-spline basis.

``(G_a)_{kl} = ∫ D^a b_k(x) · D^a b_l(x) dx`` for ``a = 0, 1, 2`` (any ``a <= n``).
The integrand is a polynomial of degree ``2(n - a) <= 2n`` on every knot span, so
Gauss–Legendre with ``n + 1`` points per span integrates it exactly (up to round-off).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray

from .basis import BSplineBasis
from .errors import InputError
from .knots import KnotVectorBasis, RationalBasis

Basis = BSplineBasis | KnotVectorBasis | RationalBasis


def gauss_points(basis: Basis, points_per_cell: int | None = None
                 ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Gauss–Legendre points and weights on every cell of ``basis``.

    Parameters
    ----------
    basis : BSplineBasis or KnotVectorBasis
        For a general knot vector the cells are its non-empty knot spans.
    points_per_cell : int, optional
        Defaults to ``n + 1``, exact for polynomials of degree ``2n + 1`` per cell
        (a rational basis sets its own, larger default: its functions are not polynomials).

    Returns
    -------
    x, w : ndarray, shape ``(cells * points_per_cell,)``
    """
    default = getattr(basis, "points_per_cell", basis.degree + 1)
    q = default if points_per_cell is None else int(points_per_cell)
    ref_x, ref_w = np.polynomial.legendre.leggauss(q)
    if isinstance(basis, (KnotVectorBasis, RationalBasis)):
        # general knot vector: one Gauss–Legendre rule per non-empty knot span
        left, width = basis.breaks[:-1, None], np.diff(basis.breaks)[:, None]
        x = left + 0.5 * width * (ref_x + 1.0)
        return x.ravel(), (0.5 * width * ref_w).ravel()
    h = basis.h
    left = np.arange(basis.cells)[:, None] * h
    x = left + 0.5 * h * (ref_x + 1.0)
    w = np.broadcast_to(0.5 * h * ref_w, x.shape)
    return x.ravel(), w.ravel().copy()


def weighted_products(basis: Basis, x: NDArray[np.float64], w: NDArray[np.float64],
                      order_left: int, order_right: int) -> sp.csr_matrix:
    """Sparse ``Σ_q w_q D^{a} b_k(x_q) D^{c} b_l(x_q)`` with ``a = order_left``, ``c = order_right``.

    Vectorised over points: each point contributes an ``(n+1) × (n+1)`` block.
    """
    top = max(order_left, order_right)
    index, values = basis.nonzero_derivatives(x, top)
    left = values[order_left] * w[:, None]
    right = values[order_right]
    blocks = left[:, :, None] * right[:, None, :]
    rows = np.broadcast_to(index[:, :, None], blocks.shape).ravel()
    cols = np.broadcast_to(index[:, None, :], blocks.shape).ravel()
    return sp.csr_matrix((blocks.ravel(), (rows, cols)), shape=(basis.size, basis.size))


def gram_matrix(basis: Basis, order: int) -> sp.csr_matrix:
    """Exact Gram matrix ``(G_a)_{kl} = ∫_0^L D^a b_k D^a b_l dx`` (sparse, banded, symmetric).

    Parameters
    ----------
    basis : BSplineBasis
    order : int
        Derivative order ``a`` with ``0 <= a <= n``.

    Examples
    --------
    >>> from splinedeform.basis import BSplineBasis
    >>> G0 = gram_matrix(BSplineBasis(2, 3, 1.0, "open"), 0)
    >>> round(float(G0.sum()), 12)   # ∫ (Σ b_k)² = L
    1.0
    """
    if not isinstance(order, (int, np.integer)) or not 0 <= order <= basis.degree:
        raise InputError(f"Gram matrix order must be an integer in 0..{basis.degree} "
                         f"(the degree), got {order!r}")
    x, w = gauss_points(basis)
    G = weighted_products(basis, x, w, order, order)
    return ((G + G.T) * 0.5).tocsr()


def integrals(basis: Basis) -> NDArray[np.float64]:
    """``∫_0^L b_k dx`` for every basis function (exact)."""
    x, w = gauss_points(basis)
    index, values = basis.nonzero(x)
    return np.bincount(index.ravel(), (values * w[:, None]).ravel(), minlength=basis.size)
