"""The first fundamental form of a surface on a 2-D tensor Gauss grid.

At every quadrature point ``(u_a, v_b)``: the covariant basis ``a_α = x_,α``, the
second derivatives ``a_αβ = x_,αβ``, the metric ``g_αβ = a_α·a_β``, its inverse
``g^αβ``, the area element ``√g = |a_1 × a_2|`` and the Christoffel symbols
``Γ^γ_αβ = a^γ·a_αβ`` with the contravariant basis ``a^γ = g^γδ a_δ``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray

from ..errors import InputError
from ..quadrature import gauss_points
from ..rational import basis_derivatives
from ..surface import Surface

Array = NDArray[np.float64]
#: derivative orders ``(p, q)``, ``p + q <= 2``, of the shape functions
ORDERS = ((0, 0), (1, 0), (0, 1), (2, 0), (1, 1), (0, 2))
DEGENERATE = 1e-9      # √g below this fraction of its largest value is a degenerate metric


@dataclass(frozen=True)
class Grid:
    """Tensor Gauss grid with the 1-D basis values and the metric of the initial surface.

    ``index_u (Qu, pu)``, ``values_u (3, Qu, pu)`` (derivative orders 0..2), likewise in v;
    ``weight (Qu, Qv)`` the parameter quadrature weights; ``a (2, Qu, Qv, 3)``,
    ``a2 (3, Qu, Qv, 3)`` for ``a_11, a_12, a_22``; ``sqrt_g``, ``g_inv (Qu, Qv, 2, 2)``,
    ``gamma (2, 3, Qu, Qv)`` = ``Γ^γ_{11}, Γ^γ_{12}, Γ^γ_{22}``.
    """

    index_u: NDArray[np.int64]
    values_u: Array
    index_v: NDArray[np.int64]
    values_v: Array
    weight: Array
    a: Array
    a2: Array
    sqrt_g: Array
    g_inv: Array
    gamma: Array
    #: ``D^p_u D^q_v R_k`` of a surface with general weights (:func:`shape_derivatives`)
    shapes: dict[tuple[int, int], Array] | None = None


def poles(surface: Surface, tol: float = 1e-10) -> tuple[str, ...]:
    """Edges whose control points all coincide (declared poles, e.g. ``"v1"`` of a half sphere)."""
    P = surface.control_points
    scale = max(1.0, float(np.abs(P).max()))
    rows = {"u0": P[0], "u1": P[-1], "v0": P[:, 0], "v1": P[:, -1]}
    return tuple(edge for edge, row in rows.items()
                 if np.max(np.linalg.norm(row - row[0], axis=-1)) <= tol * scale)


def check_metric(surface: Surface, samples: int = 4) -> None:
    """Refuse a first fundamental form that degenerates away from a declared pole.

    Samples ``√g = |x_u × x_v|`` on ``samples`` points per cell and both ends in each
    direction; a point with ``√g <= DEGENERATE · max √g`` that does not lie on a pole edge
    (see :func:`poles`) raises :class:`InputError` naming the parameter point.
    """
    bu, bv = surface.basis_u, surface.basis_v
    u = np.linspace(0.0, bu.length, samples * bu.cells + 1)
    v = np.linspace(0.0, bv.length, samples * bv.cells + 1)
    cross = np.cross(surface.evaluate_grid(u, v, 1, 0), surface.evaluate_grid(u, v, 0, 1))
    area = np.linalg.norm(cross, axis=-1)
    bad = area <= DEGENERATE * area.max()
    on_pole = {"u0": (slice(0, 1), slice(None)), "u1": (slice(-1, None), slice(None)),
               "v0": (slice(None), slice(0, 1)), "v1": (slice(None), slice(-1, None))}
    for edge in poles(surface):
        bad[on_pole[edge]] = False
    if np.any(bad):
        i, j = np.argwhere(bad)[0]
        raise InputError(
            f"the first fundamental form of surface {surface.name!r} degenerates at parameter "
            f"(u, v) = ({u[i]:.6g}, {v[j]:.6g}): |x_u × x_v| = {area[i, j]:.3g} there. The "
            "surface physics needs a regular surface; a pole is allowed only as a "
            "whole edge whose control points coincide")


def grid(surface: Surface, extra_points: int = 2) -> Grid:
    """Gauss grid with ``n + 1 + extra_points`` points per cell and direction, and its metric.

    The integrands are rational in the parameters (the inverse metric), so the rule is not
    exact; ``extra_points`` beyond the polynomial rule keeps its error below the
    discretisation error.
    """
    check_metric(surface)
    bu, bv = surface.basis_u, surface.basis_v
    xu, wu = gauss_points(bu, bu.degree + 1 + extra_points)
    xv, wv = gauss_points(bv, bv.degree + 1 + extra_points)
    iu, Bu = bu.nonzero_derivatives(xu, 2)
    iv, Bv = bv.nonzero_derivatives(xv, 2)
    P = surface.control_points
    n_u, n_v = P.shape[:2]

    def collocation(index: NDArray[np.int64], values: Array, n: int) -> sp.csr_matrix:
        rows = np.broadcast_to(np.arange(index.shape[0])[:, None], index.shape)
        return sp.csr_matrix((values.ravel(), (rows.ravel(), index.ravel())),
                             shape=(index.shape[0], n))

    shapes = None
    if surface.net_weights is not None:       # the rational basis R_k of general weights
        _, R = basis_derivatives(iu[:, None], Bu[:, :, None], iv[None], Bv[:, None],
                                 surface.net_weights, ORDERS)
        shapes = {k: R[k] for k in ORDERS}

    def derivative(p: int, q: int) -> Array:
        if shapes is not None:      # homogeneous coordinates and the quotient rule
            return surface.evaluate_grid(xu, xv, p, q)
        # x_{,u^p v^q} = B_u^(p) P B_v^(q)ᵀ per coordinate, two sparse products
        tmp = (collocation(iu, Bu[p], n_u) @ P.reshape(n_u, -1)).reshape(-1, n_v, 3)
        out = collocation(iv, Bv[q], n_v) @ tmp.transpose(1, 0, 2).reshape(n_v, -1)
        return np.asarray(out).reshape(len(xv), len(xu), 3).transpose(1, 0, 2)

    a = np.stack([derivative(1, 0), derivative(0, 1)])
    a2 = np.stack([derivative(2, 0), derivative(1, 1), derivative(0, 2)])
    g = np.einsum("iabc,jabc->abij", a, a)
    det = g[..., 0, 0] * g[..., 1, 1] - g[..., 0, 1] ** 2
    sqrt_g = np.sqrt(np.maximum(det, 0.0))
    g_inv = np.stack([np.stack([g[..., 1, 1], -g[..., 0, 1]], -1),
                      np.stack([-g[..., 1, 0], g[..., 0, 0]], -1)], -2) / det[..., None, None]
    contra = np.einsum("abij,jabc->iabc", g_inv, a)               # a^γ
    gamma = np.einsum("iabc,kabc->ikab", contra, a2)              # Γ^γ_{(11,12,22)}
    return Grid(iu, Bu, iv, Bv, wu[:, None] * wv[None, :], a, a2, sqrt_g, g_inv, gamma, shapes)


def shape_derivatives(G: Grid) -> dict[tuple[int, int], Array]:
    """``D^p_u D^q_v N_k`` at every grid point, ``(Qu, Qv, pu·pv)`` for ``p + q <= 2``
    (the rational ``R_k`` of general weights, computed with the grid)."""
    if G.shapes is not None:
        return G.shapes
    out = {}
    for p, q in ORDERS:
        values = G.values_u[p][:, None, :, None] * G.values_v[q][None, :, None, :]
        out[p, q] = values.reshape(values.shape[0], values.shape[1], -1)
    return out


def global_index(G: Grid, n_v: int) -> NDArray[np.int64]:
    """Flat control point index ``k n_v + l`` of each local function, ``(Qu, Qv, pu·pv)``."""
    idx = G.index_u[:, None, :, None] * n_v + G.index_v[None, :, None, :]
    return idx.reshape(idx.shape[0], idx.shape[1], -1)


def _merge_runs(index: NDArray[np.int64], blocks: Array, axis: int
                ) -> tuple[NDArray[np.int64], Array]:
    """Sum the blocks of consecutive grid points along ``axis`` that share their unknowns.

    The Gauss points of one knot span have the same local → global index, so their blocks
    add before the sparse assembly (fewer COO entries: one block per span, not per point).
    """
    idx, blk = np.moveaxis(index, axis, 0), np.moveaxis(blocks, axis, 0)
    change = np.any(idx[1:] != idx[:-1], axis=tuple(range(1, idx.ndim)))
    starts = np.r_[0, np.nonzero(change)[0] + 1]
    return (np.moveaxis(idx[starts], 0, axis),
            np.moveaxis(np.add.reduceat(blk, starts, axis=0), 0, axis))


def assemble(index: NDArray[np.int64], blocks: Array, size: int) -> sp.csr_matrix:
    """Sum per-point dense blocks ``blocks[..., k, l]`` into a symmetric sparse ``size²`` matrix.

    ``index[a, b, k]`` is the global unknown of local ``k`` at grid point ``(a, b)``;
    blocks of points sharing their unknowns are summed first, then duplicates add
    (COO → CSR).
    """
    for axis in (0, 1):
        index, blocks = _merge_runs(index, blocks, axis)
    rows = np.broadcast_to(index[..., :, None], blocks.shape).ravel()
    cols = np.broadcast_to(index[..., None, :], blocks.shape).ravel()
    A = sp.coo_matrix((blocks.ravel(), (rows, cols)), shape=(size, size)).tocsr()
    return ((A + A.T) * 0.5).tocsr()
