"""Exact one-dimensional Gram matrices of a B-spline basis.

``(G_a)_{kl} = ∫ D^a b_k(x) · D^a b_l(x) dx`` for ``a = 0, 1, 2`` (any ``a <= n``).
The integrand is a polynomial of degree ``2(n - a) <= 2n`` on every knot span, so
Gauss–Legendre with ``n + 1`` points per span integrates it exactly (up to round-off).

The Gram matrices of a basis are kept in the bounded ``gram`` cache of
:mod:`splinedeform.construction_cache` (keyed by :func:`~splinedeform.construction_cache.basis_key`
and the order; read-only there, each caller gets a copy);
:func:`~splinedeform.construction_cache.clear_caches` empties it.
"""

from __future__ import annotations

from typing import Iterable

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray

from .basis import BSplineBasis
from .construction_cache import BoundedCache, basis_key, read_only
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
    return gram_set(basis, [order])[0]


_GRAMS = BoundedCache("gram", 256, 64 * 2**20,
                      lambda G: G.data.nbytes + G.indices.nbytes + G.indptr.nbytes)


def gram_set(basis: Basis, orders: Iterable[int]) -> list[sp.csr_matrix]:
    """The Gram matrices ``G_a`` of :func:`gram_matrix` for each order ``a`` in ``orders``
    (copies of the cached ones; those not cached from one evaluation of the basis)."""
    orders = list(orders)
    for order in orders:
        if not isinstance(order, (int, np.integer)) or not 0 <= order <= basis.degree:
            raise InputError(f"Gram matrix order must be an integer in 0..{basis.degree} "
                             f"(the degree), got {order!r}")
    key = basis_key(basis)
    made: dict[int, sp.csr_matrix] = {}

    def make(order: int) -> sp.csr_matrix:
        if not made:
            made.update(zip(orders, _symmetric_grams(basis, orders)))
        return made[order]

    return [_GRAMS.get((key, int(a)), lambda a=a: make(a)).copy() for a in orders]


def _symmetric_grams(basis: Basis, orders: list[int]) -> list[sp.csr_matrix]:
    """``(G + Gᵀ) / 2`` of ``G = Σ_q w_q D^a b(x_q) D^a b(x_q)ᵀ`` for each order ``a``, on
    one shared pattern (exact zeros after the symmetrisation dropped), read-only.

    One evaluation of the basis at the Gauss points serves every order: each point
    contributes an ``(n+1) × (n+1)`` block at the pairs of its non-zero functions, summed
    into the sorted pattern of all pairs (``np.bincount``).
    """
    x, w = gauss_points(basis)
    index, values = basis.nonzero_derivatives(x, max(orders))
    size = basis.size
    keys = (index[:, :, None] * size + index[:, None, :]).ravel()
    pattern, slot = np.unique(keys, return_inverse=True)
    rows, cols = np.divmod(pattern, size)
    transposed = np.searchsorted(pattern, cols * size + rows)   # the pattern is symmetric
    out = []
    for order in orders:
        left = values[order] * w[:, None]
        blocks = left[:, :, None] * values[order][:, None, :]
        G = np.bincount(slot.ravel(), blocks.ravel(), minlength=pattern.size)
        G = (G + G[transposed]) * 0.5
        keep = G != 0
        indptr = np.zeros(size + 1, dtype=np.int32)
        np.cumsum(np.bincount(rows[keep], minlength=size), out=indptr[1:])
        matrix = sp.csr_matrix((G[keep], cols[keep].astype(np.int32), indptr),
                               shape=(size, size))
        matrix.has_canonical_format = True
        read_only(matrix.data, matrix.indices, matrix.indptr)
        out.append(matrix)
    return out


def integrals(basis: Basis) -> NDArray[np.float64]:
    """``∫_0^L b_k dx`` for every basis function (exact)."""
    x, w = gauss_points(basis)
    index, values = basis.nonzero(x)
    return np.bincount(index.ravel(), (values * w[:, None]).ravel(), minlength=basis.size)
