"""Quadrature over a trimmed region: tensor Gauss on inside cells, Gauss–Green on cut cells.

On a cut cell ``C = [x_0, x_1] × [y_0, y_1]`` Green's theorem gives

.. math:: ∫_{C∩Ω} f \\,dx\\,dy = ∮_{∂(C∩Ω)} F(x, y)\\, dy, \\qquad
          F(x, y) = ∫_{x_0}^{x} f(s, y)\\, ds

(Sommariva & Vianello's Gauss–Green cubature). ``∂(C∩Ω)`` is made of the trim pieces in
``C`` (run with ``Ω`` on their left) and of the parts of ``∂C`` inside ``Ω``; of these only
the right edge ``x = x_1`` contributes (``F = 0`` on the left edge, ``dy = 0`` on the
horizontal ones). Each boundary Gauss point ``γ(t_k)`` with weight ``ω_k`` becomes ``q``
points ``s_l = x_0 + (x(t_k) - x_0)(1 + ξ_l)/2`` with weights
``ω_k y'(t_k) (x(t_k) - x_0)/2 · ϖ_l``. For a polynomial ``f`` of degree ``p`` and straight
pieces the rule is exact once ``q >= (p + 2)/2``; on circular arcs the boundary integrand is
an entire function of the angle and Gauss converges faster than any power. Weights may be
negative (points lie anywhere in the cell, also outside ``Ω``, where ``f`` is the cell's
polynomial continued).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError
from .cells import CUT, INSIDE, Grid, classify_cells, loop_pieces
from .loops import CircleLoop, TrimDomain
from .spline_loop import SplineLoop


@dataclass(frozen=True)
class TrimQuadrature:
    """Points ``(u, v)`` (shape ``(Q, 2)``), weights ``(Q,)`` and the cell ``(Q, 2)`` of each."""

    points: NDArray[np.float64]
    weights: NDArray[np.float64]
    cell: NDArray[np.int64]
    classes: NDArray[np.int64]

    def integrate(self, values: NDArray[np.float64]) -> float:
        """``Σ_q w_q f(x_q)``."""
        return float(np.dot(self.weights, values))


def _vertical_crossings(domain: TrimDomain, x: float) -> NDArray[np.float64]:
    """Heights ``y`` where the line ``u = x`` meets any trim loop."""
    ys = []
    for loop in domain.loops:
        if isinstance(loop, CircleLoop):
            s = (x - loop.centre[0]) / loop.radius
            if abs(s) < 1:
                dy = loop.radius * np.sqrt(1 - s * s)
                ys += [loop.centre[1] - dy, loop.centre[1] + dy]
        elif isinstance(loop, SplineLoop):
            span, tau = loop.crossings(0, x)
            ys += list(loop.evaluate(span + tau)[0][:, 1])
        else:
            a, b = loop.segments()
            straddle = (a[:, 0] > x) != (b[:, 0] > x)
            t = (x - a[straddle, 0]) / (b[straddle, 0] - a[straddle, 0])
            ys += list(a[straddle, 1] + t * (b[straddle, 1] - a[straddle, 1]))
    return np.array(ys, dtype=float)


def cell_gauss(cells: NDArray[np.int64], grid: Grid, order: int
               ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.int64]]:
    """Tensor Gauss–Legendre, ``order × order`` points, on whole cells ``(C, 2)``: points
    ``(C order², 2)``, weights and the cell of each point."""
    xi, om = np.polynomial.legendre.leggauss(order)
    lo, h = grid.sides(cells)
    ref = np.stack(np.meshgrid(xi, xi, indexing="ij"), axis=-1).reshape(-1, 2)
    ref_w = np.outer(om, om).ravel() * 0.25
    points = (lo[:, None, :] + 0.5 * (ref[None] + 1) * h[:, None, :]).reshape(-1, 2)
    weights = (ref_w[None] * h.prod(axis=1)[:, None]).ravel()
    return points, weights, np.repeat(cells, len(ref), axis=0)


def trim_quadrature(domain: TrimDomain, grid: Grid, order: int) -> TrimQuadrature:
    """Quadrature of ``Ω ∩ [0, L_u] × [0, L_v]`` cell by cell.

    Parameters
    ----------
    order : int
        Gauss–Legendre points per direction: ``order`` × ``order`` on inside cells (exact
        for degree ``2 order - 1`` per variable), ``order`` along each boundary piece and
        ``order`` across for cut cells.
    """
    if not isinstance(order, (int, np.integer)) or order < 1:
        raise InputError(f"quadrature order must be an integer >= 1, got {order!r}")
    xi, om = np.polynomial.legendre.leggauss(order)
    x_lines = grid.lines(0)
    pieces = loop_pieces(domain, grid)
    classes = classify_cells(domain, grid, pieces)

    p_in, w_in, c_in = cell_gauss(np.argwhere(classes == INSIDE), grid, order)

    # boundary pieces of the cut cells: trim pieces and right edges inside Ω
    t = 0.5 * (pieces.lo + pieces.hi)[:, None] + 0.5 * (pieces.hi - pieces.lo)[:, None] * xi
    point, tangent = pieces.evaluate(t)
    dt = 0.5 * (pieces.hi - pieces.lo)[:, None] * om
    bx, by, bw = point[..., 0], point[..., 1], dt * tangent[..., 1]
    bcell = np.broadcast_to(pieces.cell[:, None, :], point.shape)
    edges_x, edges_y, edges_w, edges_c = [bx.ravel()], [by.ravel()], [bw.ravel()], [
        bcell.reshape(-1, 2)]
    y_lines = grid.lines(1)
    for i in np.unique(np.argwhere(classes == CUT)[:, 0]):
        x1 = x_lines[i + 1]
        cut_rows = np.flatnonzero(classes[i] == CUT)
        ys = np.unique(np.concatenate([y_lines, _vertical_crossings(domain, x1)]))
        lo, hi = ys[:-1], ys[1:]
        mid = 0.5 * (lo + hi)
        row = np.minimum(grid.cell_of(mid, 1), grid.cells[1] - 1)
        keep = domain.contains(np.stack([np.full_like(mid, x1), mid], axis=-1)) & np.isin(
            row, cut_rows) & (hi > lo)
        lo, hi, row = lo[keep], hi[keep], row[keep]
        y = 0.5 * (lo + hi)[:, None] + 0.5 * (hi - lo)[:, None] * xi
        edges_x.append(np.full(y.size, x1))
        edges_y.append(y.ravel())
        edges_w.append((0.5 * (hi - lo)[:, None] * om).ravel())
        edges_c.append(np.stack([np.full(y.size, i), np.repeat(row, order)], axis=-1))
    bx, by = np.concatenate(edges_x), np.concatenate(edges_y)
    bw, bc = np.concatenate(edges_w), np.concatenate(edges_c)
    x0 = x_lines[bc[:, 0]]
    half = 0.5 * (bx - x0)
    s = x0[:, None] + half[:, None] * (1 + xi)
    p_cut = np.stack([s, np.broadcast_to(by[:, None], s.shape)], axis=-1).reshape(-1, 2)
    w_cut = ((bw * half)[:, None] * om).ravel()
    c_cut = np.repeat(bc, order, axis=0)
    # points of the cut rule lie in their cell's closure, possibly outside Ω
    return TrimQuadrature(np.concatenate([p_in, p_cut]), np.concatenate([w_in, w_cut]),
                          np.concatenate([c_in, c_cut]), classes)
