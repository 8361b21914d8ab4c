"""Tensor-product B-splines and their partial derivatives at scattered points, as sparse rows.

Row ``q`` of the matrix for the orders ``(a, b)`` holds
``D^a b_k(u_q) D^b b_l(v_q)`` in column ``k n_v + l`` (the row-major flattening of the
net), for the ``(n_u+1)(n_v+1)`` functions not vanishing at the point.
"""

from __future__ import annotations

from typing import Any, Iterable

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray

Orders = tuple[int, int]


def tensor_values(bases: tuple, p: NDArray[np.float64], orders: Iterable[Orders]
                  ) -> dict[Orders, sp.csr_matrix]:
    """``{(a, b): B_ab}`` with ``(B_ab)_{q, k n_v + l} = D^a b_k(p_q0) D^b b_l(p_q1)``.

    ``bases`` are the two 1-D bases (anything with ``nonzero_derivatives`` and ``size``);
    ``p`` has shape ``(Q, 2)``. One evaluation of each direction up to the highest order.
    """
    orders = list(orders)
    bu, bv = bases
    top_u, top_v = max(a for a, _ in orders), max(b for _, b in orders)
    iu, du = bu.nonzero_derivatives(p[:, 0], top_u)
    iv, dv = bv.nonzero_derivatives(p[:, 1], top_v)
    cols = (iu[:, :, None] * bv.size + iv[:, None, :]).reshape(len(p), -1)
    indptr = np.arange(0, cols.size + 1, cols.shape[1])
    shape = (len(p), bu.size * bv.size)
    out = {}
    for a, b in orders:
        vals = (du[a][:, :, None] * dv[b][:, None, :]).reshape(len(p), -1)
        out[(a, b)] = sp.csr_matrix((vals.ravel(), cols.ravel(), indptr), shape=shape)
    return out


def surface_values(surface: Any, p: NDArray[np.float64], orders: Iterable[Orders]
                   ) -> dict[Orders, sp.csr_matrix]:
    """:func:`tensor_values` of the basis of ``surface``: its B-splines (or per-direction
    rational bases), or with NURBS weights ``w_kl`` that do not factor the rational
    ``R_kl = w_kl b_k b_l / W`` and its derivatives by Leibniz' rule
    (:func:`splinedeform.rational.basis_derivatives`), in the same sparse layout."""
    orders = list(orders)
    bases = (surface.basis_u, surface.basis_v)
    if surface.net_weights is None:
        return tensor_values(bases, p, orders)
    from ..rational import basis_derivatives

    bu, bv = bases
    iu, du = bu.nonzero_derivatives(p[:, 0], max(a for a, _ in orders))
    iv, dv = bv.nonzero_derivatives(p[:, 1], max(b for _, b in orders))
    cols, R = basis_derivatives(iu, du, iv, dv, np.asarray(surface.net_weights, float), orders)
    indptr = np.arange(0, cols.size + 1, cols.shape[1])
    shape = (len(p), bu.size * bv.size)
    return {ab: sp.csr_matrix((R[ab].ravel(), cols.ravel(), indptr), shape=shape)
            for ab in orders}
