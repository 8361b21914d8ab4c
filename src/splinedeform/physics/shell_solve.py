"""Sparse Cholesky-like factorisation of the shell's stiffness in a nested dissection order.

The stiffness couples control points ``(i, j)`` and ``(i', j')`` with ``|i − i'| <= p_u``
and ``|j − j'| <= p_v``, so ``p`` consecutive lines of control points separate the net in
two. Nested dissection orders each half first, recursively, and the separator last;
a periodic direction is cut open by two separators. Each reduced unknown takes the rank
of the control point it moves (the first row of its column of ``T``). The symmetric
positive definite matrix is then factored without pivoting (SuperLU in symmetric mode,
the order kept), which on a 2-D net fills far less than a column ordering of the whole
``3n`` system.

A static load on a shell with free rigid motions ``R`` (``K R = 0``) does no work on them
(``Rᵀ F = 0``, checked by the model), so holding ``k`` unknowns where ``R`` is best
conditioned (pivoted QR of ``Rᵀ``) gives a regular system whose answer differs from the
one with ``Rᵀ M d = 0`` by a rigid motion only: ``d = d' − R (Rᵀ M R)⁻¹ Rᵀ M d'``.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from numpy.typing import NDArray

Array = NDArray[np.float64]
Index = NDArray[np.int64]
#: subdomains of at most this many control points are ordered as they are
LEAF = 48


def dissection_ranks(n_u: int, n_v: int, width: tuple[int, int], periodic_u: bool,
                     periodic_v: bool = False) -> Index:
    """Rank of every control point ``i n_v + j`` in a nested dissection order."""
    order: list[Index] = []

    def points(I: Index, J: Index) -> Index:
        return (I[:, None] * n_v + J[None, :]).ravel()

    def rect(I: Index, J: Index) -> None:
        along_u = len(I) >= len(J)
        lines, w = (I, width[0]) if along_u else (J, width[1])
        m = len(lines) // 2
        if len(I) * len(J) <= LEAF or len(lines) - m - w < 1 or m < 1:
            order.append(points(I, J))
            return
        a, s, b = lines[:m], lines[m:m + w], lines[m + w:]
        if along_u:
            rect(a, J), rect(b, J)
            order.append(points(s, J))
        else:
            rect(I, a), rect(I, b)
            order.append(points(I, s))

    I, J = np.arange(n_u), np.arange(n_v)
    cut_u, cut_v = [], []
    if periodic_u and n_u > 2 * width[0] + 2:            # two separators open the ring
        h = n_u // 2
        cut_u = [np.arange(width[0]), np.arange(h, h + width[0])]
        pieces_u = [np.arange(width[0], h), np.arange(h + width[0], n_u)]
    else:
        pieces_u = [I]
    if periodic_v and n_v > 2 * width[1] + 2:
        h = n_v // 2
        cut_v = [np.arange(width[1]), np.arange(h, h + width[1])]
        pieces_v = [np.arange(width[1], h), np.arange(h + width[1], n_v)]
    else:
        pieces_v = [J]
    for pu in pieces_u:
        for pv in pieces_v:
            rect(pu, pv)
    if cut_v:
        for pu in pieces_u:
            order.append(points(pu, np.concatenate(cut_v)))
    if cut_u:
        order.append(points(np.concatenate(cut_u), J))
    nodes = np.concatenate(order)
    rank = np.empty(n_u * n_v, dtype=np.int64)
    rank[nodes] = np.arange(nodes.size)
    return rank


def unknown_order(T: sp.spmatrix, rank: Index, unknowns: Index) -> Index:
    """``unknowns`` sorted by the rank of the control point each moves (ties kept)."""
    T = sp.csc_matrix(T)
    point = T.indices[T.indptr[:-1]] // 3
    return unknowns[np.lexsort((np.arange(unknowns.size), rank[point[unknowns]]))]


def static_displacement(K: sp.spmatrix, M: sp.spmatrix, rigid: Array, F: Array,
                        order: Index) -> Array | None:
    """``K d = F`` with ``Rᵀ M d = 0`` by the held-unknowns route; None if that fails.

    ``order`` is a permutation of all unknowns (:func:`unknown_order`); the held ones are
    dropped from it. None (the caller's general solve decides) when the held system is
    singular or its answer's residual exceeds ``1e-8 ‖F‖``.
    """
    k = rigid.shape[1]
    held = sla.qr(rigid.T, pivoting=True, mode="economic")[2][:k] if k else np.zeros(0, int)
    keep = order[~np.isin(order, held)]
    A = sp.csc_matrix(K)[keep][:, keep].tocsc()
    try:
        lu = spla.splu(A, permc_spec="NATURAL", diag_pivot_thresh=0.0,
                       options={"SymmetricMode": True})
    except RuntimeError:
        return None
    d = np.zeros(K.shape[0])
    d[keep] = lu.solve(F[keep])
    if k:
        MR = M @ rigid
        d -= rigid @ np.linalg.solve(rigid.T @ MR, MR.T @ d)
    if not np.all(np.isfinite(d)) or \
            np.linalg.norm(K @ d - F) > 1e-8 * max(np.linalg.norm(F), 1e-300):
        return None
    return d
