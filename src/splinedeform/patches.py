"""Bézier patches of a tensor-product surface: its evaluation as a user calls it.

On the cell ``[u_i, u_{i+1}] × [v_j, v_{j+1}]`` (local parameters ``s, t ∈ [0, 1]``) the
surface and its derivatives are tensor-product Bernstein polynomials:

.. math:: \\partial_u^{a}\\partial_v^{b} x(u, v) = \\sum_{k,l} Q^{ab}_{ij,kl}\\,
          B_{k,n_u-a}(s)\\, B_{l,n_v-b}(t), \\qquad
          Q^{ab}_{ij,kl} = \\sum_{r,q} β^{(a)}_{i,r,k}\\, γ^{(b)}_{j,q,l}\\, p_{f_i+r,\\, g_j+q}

with the per-span Bernstein coefficients ``β``, ``γ`` of the two bases
(:mod:`splinedeform.spans`; derivative factors included) and ``f_i``, ``g_j`` the first
functions of the spans. The patches ``Q`` are computed once per surface and order (they
are a property of the immutable control net), once the surface has been asked for as many
points as it has cells (:func:`patches_when_worth`), and kept while they take at most
:data:`MAX_PATCH_VALUES` numbers; an evaluation is then one contiguous gather of
``(n_u+1)(n_v+1)`` points per parameter pair and one small contraction, or for a single
pair given as two floats a handful of float operations and one matrix-vector product.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from .spans import bernstein, scalar_bernstein

Array = NDArray[np.float64]

PATCH_BLOCK = 2048
"""Parameter pairs per block of :func:`evaluate_patches` (measured fastest of 256 … 2048)."""

MAX_PATCH_VALUES = 8 * 2**20
"""Most numbers the patches of one surface and one derivative order may take (64 MiB)."""


def patch_net(surface: Any, du: int, dv: int) -> Array | None:
    """Patches ``Q^{du,dv}`` of ``surface``, shape ``(cells_u, cells_v, 3, K)``.

    ``K = (n_u+1-du)(n_v+1-dv)``: the coefficients ``(k, l)`` of each coordinate side by
    side, ``k``-major, so that a point is one product ``Q_ij w`` with ``w_kl = B_k(s) B_l(t)``.
    ``None`` where a basis has no polynomial span form (a rational basis), an order
    exceeds a degree (the derivative is zero), or the patches would be too large.
    """
    key = ("patches", du, dv)
    if key in surface._cache:
        return surface._cache[key]
    bu, bv = surface.basis_u, surface.basis_v
    Q = None
    if (getattr(bu, "form", None) is not None and getattr(bv, "form", None) is not None
            and du <= bu.degree and dv <= bv.degree):
        Cu, Cv = bu.form.coefficients[du], bv.form.coefficients[dv]   # (cells, n+1, n+1-j)
        if Cu.shape[0] * Cv.shape[0] * Cu.shape[2] * Cv.shape[2] * 3 <= MAX_PATCH_VALUES:
            P = surface.control_points
            along_v = np.einsum("jql,ujqc->ujlc", Cv, P[:, bv.span_functions()])
            Q = np.einsum("irk,irjlc->ijckl", Cu, along_v[bu.span_functions()])
            Q = np.ascontiguousarray(Q).reshape(Q.shape[:3] + (-1,))
            Q.setflags(write=False)
    surface._cache[key] = Q
    return Q


def patches_when_worth(surface: Any, du: int, dv: int, count: int) -> Array | None:
    """:func:`patch_net` once the surface has been asked for as many points as it has cells.

    Computing the patches costs about as much as evaluating one point per cell the direct
    way, so they are computed once ``count`` points (summed over the calls of one order)
    reach the number of cells: a single point on a new surface (``sol.surface(t).evaluate(u,
    v)``) never pays for them, and many points pay at most about twice the direct cost.
    """
    key = ("patches", du, dv)
    if key in surface._cache:
        return surface._cache[key]
    seen = surface._cache.get(("points", du, dv), 0) + count
    surface._cache[("points", du, dv)] = seen
    if seen < surface.basis_u.cells * surface.basis_v.cells:
        return None
    return patch_net(surface, du, dv)


def evaluate_patches(Q: Array, degrees: tuple[int, int], basis_u: Any, basis_v: Any,
                     u: Array, v: Array) -> Array:
    """``Σ_kl Q_{ij,kl} B_k(s) B_l(t)`` at flat parameter arrays ``u``, ``v``; shape ``(N, 3)``.

    ``degrees`` are those of the patches, ``(n_u - du, n_v - dv)``.
    """
    span_u, s = basis_u.locate(u)
    span_v, t = basis_v.locate(v)
    cells_v = Q.shape[1]
    flat = Q.reshape((Q.shape[0] * cells_v,) + Q.shape[2:])        # (cells, 3, K)
    cell = span_u * cells_v + span_v
    out = np.empty((u.size, 3))
    for start in range(0, u.size, PATCH_BLOCK):
        block = slice(start, start + PATCH_BLOCK)
        # w_kl = B_k(s) B_l(t) formed with the points last (contiguous), then one transpose
        weights = (bernstein(s[block], degrees[0])[:, None, :]
                   * bernstein(t[block], degrees[1])[None, :, :])        # (k, l, B)
        np.einsum("pck,pk->pc", np.take(flat, cell[block], axis=0),
                  np.ascontiguousarray(weights.reshape(-1, weights.shape[2]).T), out=out[block])
    return out


def evaluate_patch_point(Q: Array, degrees: tuple[int, int], basis_u: Any, basis_v: Any,
                         u: float, v: float) -> Array:
    """One point ``Σ_kl Q_{ij,kl} B_k(s) B_l(t)`` from plain floats; shape ``(3,)``."""
    i, s = basis_u.locate_scalar(u)
    j, t = basis_v.locate_scalar(v)
    weights_v = scalar_bernstein(t, degrees[1])
    weights = [a * b for a in scalar_bernstein(s, degrees[0]) for b in weights_v]
    return Q[i, j].dot(np.array(weights))
