"""Knot-grid cells against a trimmed region: inside, outside or cut by a trim loop.

The grid has cells ``[x_i, x_{i+1}] × [y_j, y_{j+1}]`` between its lines (the knots'
breakpoints; ``x_i = i h_u`` for equal cells). Every trim loop is split
at the grid lines into *pieces*, each inside one cell; a cell holding a piece is **cut**,
any other cell is **inside** or **outside** as its centre is.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError
from .loops import CircleLoop, PolygonLoop, TrimDomain
from .spline_loop import SplineLoop

INSIDE, OUTSIDE, CUT = 1, 0, 2
#: distance (relative to the diagonal of the parameter rectangle) within which a loop is
#: taken to run along its sides (a CAD face's outer loop) rather than outside them
SIDE_TOL = 1e-9


@dataclass(frozen=True)
class Grid:
    """``cells = (m_u, m_v)`` cells on ``[0, L_u] × [0, L_v]``: equal ones, or those between
    the ``breaks`` (two increasing arrays from 0 to ``L``, ``m + 1`` values each)."""

    cells: tuple[int, int]
    lengths: tuple[float, float] = (1.0, 1.0)
    breaks: tuple[NDArray[np.float64], NDArray[np.float64]] | None = None

    @classmethod
    def of_breaks(cls, breaks_u: NDArray[np.float64], breaks_v: NDArray[np.float64]) -> "Grid":
        """The grid of the lines ``breaks_u``, ``breaks_v`` (each from 0)."""
        b = tuple(np.asarray(x, dtype=float) for x in (breaks_u, breaks_v))
        if any(x.ndim != 1 or len(x) < 2 or x[0] != 0.0 or np.any(np.diff(x) <= 0) for x in b):
            raise InputError("a grid's lines must be increasing from 0")
        return cls((len(b[0]) - 1, len(b[1]) - 1), (float(b[0][-1]), float(b[1][-1])), b)

    @property
    def h(self) -> tuple[float, float]:
        """The cells' sides (equal cells; the smallest of each direction otherwise)."""
        if self.breaks is not None:
            return tuple(float(np.diff(x).min()) for x in self.breaks)  # type: ignore[return-value]
        return self.lengths[0] / self.cells[0], self.lengths[1] / self.cells[1]

    def lines(self, axis: int) -> NDArray[np.float64]:
        if self.breaks is not None:
            return self.breaks[axis]
        return np.arange(self.cells[axis] + 1) * (self.lengths[axis] / self.cells[axis])

    def cell_of(self, x: NDArray[np.float64], axis: int) -> NDArray[np.int64]:
        """The cell ``i`` with ``x_i <= x < x_{i+1}`` along ``axis`` (-1 before the first
        line, ``m`` from the last on)."""
        return np.searchsorted(self.lines(axis), x, side="right").astype(int) - 1

    def centres(self) -> NDArray[np.float64]:
        """Cell centres, shape ``(m_u, m_v, 2)``."""
        cu, cv = (0.5 * (x[1:] + x[:-1]) for x in (self.lines(0), self.lines(1)))
        return np.stack(np.meshgrid(cu, cv, indexing="ij"), axis=-1)

    def sides(self, cells: NDArray[np.int64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Lower corners and sides ``(C, 2)`` of the cells ``(C, 2)``."""
        lo = np.stack([self.lines(a)[cells[:, a]] for a in (0, 1)], axis=-1)
        hi = np.stack([self.lines(a)[cells[:, a] + 1] for a in (0, 1)], axis=-1)
        return lo, hi - lo


@dataclass(frozen=True)
class Pieces:
    """Pieces of trim loops, each in one cell: a curve ``γ(t)`` for ``t ∈ [lo, hi]``.

    ``kind`` 0 is a straight piece from ``start`` to ``end`` (``t ∈ [0, 1]``), 1 an arc of
    the circle ``centre, radius`` with angles ``t``, 2 a span of a spline loop, the
    polynomial ``Σ_e poly[e] t^e`` (``t ∈ [0, 1]``); ``cell`` the ``(i, j)`` of its cell;
    ``loop`` the index of its loop in :attr:`TrimDomain.loops` (0 the outer loop);
    ``span`` the polygon segment or spline span it lies on (0 on a circle).
    """

    kind: NDArray[np.int64]
    lo: NDArray[np.float64]
    hi: NDArray[np.float64]
    start: NDArray[np.float64]
    end: NDArray[np.float64]
    centre: NDArray[np.float64]
    radius: NDArray[np.float64]
    cell: NDArray[np.int64]
    poly: NDArray[np.float64]
    loop: NDArray[np.int64] | None = None
    span: NDArray[np.int64] | None = None

    def evaluate(self, t: NDArray[np.float64]
                 ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Points ``γ(t)`` and tangents ``γ'(t)`` for ``t`` of shape ``(pieces, q)``."""
        line = self.kind[:, None] == 0
        d = self.end - self.start
        p_line = self.start[:, None] + t[..., None] * d[:, None]
        ang = np.where(line, 0.0, t)
        r = self.radius[:, None, None]
        circ = np.stack([np.cos(ang), np.sin(ang)], axis=-1)
        p_arc = self.centre[:, None] + r * circ
        dp_arc = r * np.stack([-np.sin(ang), np.cos(ang)], axis=-1)
        point = np.where(line[..., None], p_line, p_arc)
        tangent = np.where(line[..., None], np.broadcast_to(d[:, None], p_line.shape), dp_arc)
        spline = self.kind == 2
        if np.any(spline):
            e = np.arange(self.poly.shape[1])
            tau = t[spline][..., None]
            C = self.poly[spline]
            point[spline] = np.einsum("pqe,pek->pqk", tau ** e, C)
            tangent[spline] = np.einsum("pqe,pek->pqk",
                                        e * tau ** np.maximum(e - 1, 0), C)
        return point, tangent


def _polygon_pieces(loop: PolygonLoop, grid: Grid) -> tuple[NDArray, ...]:
    a, b = loop.segments()
    d = b - a
    cuts = [np.zeros((len(a), 1)), np.ones((len(a), 1))]
    for axis in (0, 1):
        g = grid.lines(axis)
        with np.errstate(divide="ignore", invalid="ignore"):
            t = (g[None] - a[:, axis, None]) / d[:, axis, None]
        cuts.append(np.where((t > 0) & (t < 1), t, np.nan))
    t = np.sort(np.concatenate(cuts, axis=1), axis=1)      # NaN sort last
    lo, hi = t[:, :-1], t[:, 1:]
    keep = np.isfinite(hi) & (hi > lo)
    seg = np.broadcast_to(np.arange(len(a))[:, None], lo.shape)[keep]
    return a[seg], b[seg], lo[keep], hi[keep], seg


def _circle_pieces(loop: CircleLoop, grid: Grid) -> tuple[NDArray, NDArray]:
    c, r = np.array(loop.centre), loop.radius
    angles = [np.array([0.0])]
    for axis in (0, 1):
        s = (grid.lines(axis) - c[axis]) / r
        s = s[np.abs(s) < 1]
        base = np.arccos(s) if axis == 0 else np.arcsin(s)
        other = -base if axis == 0 else np.pi - base
        angles += [base, other]
    theta = np.unique(np.mod(np.concatenate(angles), 2 * np.pi))
    theta = np.append(theta, theta[0] + 2 * np.pi)
    lo, hi = theta[:-1], theta[1:]
    if loop.sense < 0:                                      # clockwise: run angles down
        lo, hi = hi, lo
    return lo, hi


def _spline_pieces(loop: SplineLoop, grid: Grid) -> tuple[NDArray, NDArray, NDArray]:
    """Spans, local ``lo``, ``hi`` of the loop's pieces between grid-line crossings."""
    spans, taus = [np.arange(loop.spans)], [np.zeros(loop.spans)]
    for axis in (0, 1):
        for value in grid.lines(axis):
            s, t = loop.crossings(axis, value)
            spans.append(s)
            taus.append(t)
    s, t = np.concatenate(spans), np.concatenate(taus)
    order = np.lexsort((t, s))
    s, t = s[order], t[order]
    nxt_s = np.append(s[1:], s[-1] + 1)
    nxt_t = np.where(nxt_s == s, np.append(t[1:], 1.0), 1.0)
    keep = nxt_t > t + 1e-13
    return s[keep], t[keep], nxt_t[keep]


def loop_pieces(domain: TrimDomain, grid: Grid, loops: tuple | None = None) -> Pieces:
    """Split every loop of ``domain`` (or the given ``loops`` of it) at the grid lines, with
    the loop's orientation kept; ``Pieces.loop`` counts in the loops split."""
    loops = domain.loops if loops is None else loops
    kinds, los, his, starts, ends, centres, radii = [], [], [], [], [], [], []
    q = 1 + max([loop.degree for loop in loops if isinstance(loop, SplineLoop)],
                default=0)
    polys, spans = [], []
    for loop in loops:
        if isinstance(loop, SplineLoop):
            span, lo, hi = _spline_pieces(loop, grid)
            spans.append(span)
            kinds.append(np.full(len(lo), 2))
            starts.append(np.zeros((len(lo), 2)))
            ends.append(np.zeros((len(lo), 2)))
            centres.append(np.zeros((len(lo), 2)))
            radii.append(np.zeros(len(lo)))
            C = np.zeros((len(lo), q, 2))
            C[:, :loop.degree + 1] = loop.power_form[span]
            polys.append(C)
            los.append(lo)
            his.append(hi)
            continue
        polys.append(None)
        if isinstance(loop, PolygonLoop):
            a, b, lo, hi, seg = _polygon_pieces(loop, grid)
            spans.append(seg)
            kinds.append(np.zeros(len(lo), int))
            starts.append(a)
            ends.append(b)
            centres.append(np.zeros((len(lo), 2)))
            radii.append(np.zeros(len(lo)))
        else:
            lo, hi = _circle_pieces(loop, grid)
            spans.append(np.zeros(len(lo), int))
            kinds.append(np.ones(len(lo), int))
            starts.append(np.zeros((len(lo), 2)))
            ends.append(np.zeros((len(lo), 2)))
            centres.append(np.broadcast_to(np.array(loop.centre), (len(lo), 2)))
            radii.append(np.full(len(lo), loop.radius))
        los.append(lo)
        his.append(hi)
    polys = [np.zeros((len(k), q, 2)) if c is None else c for c, k in zip(polys, kinds)]
    pieces = Pieces(np.concatenate(kinds), np.concatenate(los), np.concatenate(his),
                    np.concatenate(starts), np.concatenate(ends), np.concatenate(centres),
                    np.concatenate(radii), np.zeros((0, 2), int), np.concatenate(polys))
    mid, _ = pieces.evaluate(0.5 * (pieces.lo + pieces.hi)[:, None])
    cells = np.array(grid.cells)
    cell = np.stack([grid.cell_of(mid[:, 0, a], a) for a in (0, 1)], axis=-1)
    # a piece along a side of the box (within SIDE_TOL) lies in the cell beside it: on
    # the far side u = L_u (or v = L_v) its midpoint's floor is one past the last cell
    slack = SIDE_TOL * float(np.hypot(*grid.lengths))
    far = (cell == cells) & (mid[:, 0] <= np.array(grid.lengths) + slack)
    near = (cell == -1) & (mid[:, 0] >= -slack)
    cell = np.where(far, cells - 1, np.where(near, 0, cell))
    if np.any(cell < 0) or np.any(cell >= cells):
        raise InputError("a trim loop leaves the parameter domain "
                         f"[0, {grid.lengths[0]:g}] × [0, {grid.lengths[1]:g}]")
    loop = np.repeat(np.arange(len(kinds)), [len(k) for k in kinds])
    return Pieces(pieces.kind, pieces.lo, pieces.hi, pieces.start, pieces.end, pieces.centre,
                  pieces.radius, cell, pieces.poly, loop, np.concatenate(spans).astype(int))


def classify_cells(domain: TrimDomain, grid: Grid, pieces: Pieces | None = None
                   ) -> NDArray[np.int64]:
    """``(m_u, m_v)`` table of :data:`INSIDE`, :data:`OUTSIDE` or :data:`CUT`."""
    pieces = loop_pieces(domain, grid) if pieces is None else pieces
    centre = grid.centres()
    table = np.where(domain.contains(centre), INSIDE, OUTSIDE)
    table[pieces.cell[:, 0], pieces.cell[:, 1]] = CUT
    return table
