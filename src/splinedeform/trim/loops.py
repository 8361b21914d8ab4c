"""Trim loops in the parameter plane ``(u, v)``: closed polygons, exact circles and closed
uniform B-spline curves (:mod:`splinedeform.trim.spline_loop`).

A trimmed region ``Ω`` is the inside of one outer loop minus the insides of its holes.
Orientation is normalised so that ``Ω`` always lies on the left of every loop: the outer
loop runs counter-clockwise, holes clockwise. A polygon's signed area
``A = ½ Σ_k (x_k y_{k+1} - x_{k+1} y_k)`` (shoelace formula) gives its orientation.

A circle is kept exact, ``γ(θ) = c + r (cos θ, sin θ)``: the same curve as the rational
quadratic NURBS circle, parametrised by angle, so points on it carry no approximation
error beyond round-off.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InputError
from .piecewise_loop import PiecewiseLoop
from .spline_loop import SplineLoop


def _points(p: ArrayLike) -> NDArray[np.float64]:
    p = np.asarray(p, dtype=float)
    if p.shape[-1:] != (2,):
        raise InputError(f"points must have shape (..., 2), got {p.shape}")
    return p


@dataclass(frozen=True)
class PolygonLoop:
    """A closed polygon through ``vertices`` (the last joins the first).

    ``vertices`` of shape ``(k, 2)``, ``k >= 3``, no repeated closing vertex needed.
    """

    vertices: NDArray[np.float64]

    def __post_init__(self) -> None:
        v = np.asarray(self.vertices, dtype=float)
        if v.ndim != 2 or v.shape[1] != 2 or v.shape[0] < 3:
            raise InputError(f"a polygon loop needs at least 3 vertices (u, v), got shape {v.shape}")
        if not np.all(np.isfinite(v)):
            raise InputError("polygon loop vertices must be finite numbers")
        if np.allclose(v[0], v[-1]):
            v = v[:-1]
        edge = np.roll(v, -1, axis=0) - v
        if np.any(np.hypot(edge[:, 0], edge[:, 1]) == 0):
            raise InputError("a polygon loop repeats a vertex (an edge of zero length)")
        object.__setattr__(self, "vertices", v)
        _check_simple(self)
        if abs(self.signed_area) <= 1e-14 * np.ptp(v, axis=0).prod():
            raise InputError("a polygon loop encloses no area")

    @property
    def signed_area(self) -> float:
        """Shoelace area ``½ Σ (x_k y_{k+1} - x_{k+1} y_k)``; > 0 when counter-clockwise."""
        x, y = self.vertices.T
        return 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))

    def oriented(self, counter_clockwise: bool) -> "PolygonLoop":
        """The same loop run counter-clockwise or clockwise."""
        if (self.signed_area > 0) == counter_clockwise:
            return self
        return PolygonLoop(self.vertices[::-1].copy())

    def segments(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Start and end points of the edges, shape ``(k, 2)`` each."""
        return self.vertices, np.roll(self.vertices, -1, axis=0)

    def encloses(self, p: ArrayLike) -> NDArray[np.bool_]:
        """Even–odd (crossing number) test of points ``p`` (shape ``S + (2,)``), vectorised."""
        p = _points(p)
        a, b = self.segments()
        x, y = p[..., 0, None], p[..., 1, None]
        straddle = (a[:, 1] > y) != (b[:, 1] > y)
        with np.errstate(divide="ignore", invalid="ignore"):
            cross_x = a[:, 0] + (y - a[:, 1]) * (b[:, 0] - a[:, 0]) / (b[:, 1] - a[:, 1])
        return (np.sum(straddle & (x < cross_x), axis=-1) % 2) == 1

    def distance(self, p: ArrayLike) -> NDArray[np.float64]:
        """Unsigned distance ``min_k |p - proj_k(p)|`` to the edges, vectorised."""
        p = _points(p)
        a, b = self.segments()
        d = b - a
        rel = p[..., None, :] - a
        t = np.clip(np.sum(rel * d, axis=-1) / np.sum(d * d, axis=-1), 0.0, 1.0)
        gap = rel - t[..., None] * d
        return np.sqrt(np.min(np.sum(gap * gap, axis=-1), axis=-1))

    def bounds(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        return self.vertices.min(axis=0), self.vertices.max(axis=0)


@dataclass(frozen=True)
class CircleLoop:
    """The exact circle ``c + r (cos θ, sin θ)``, run counter-clockwise (``sense = +1``)
    or clockwise (``sense = -1``)."""

    centre: tuple[float, float]
    radius: float
    sense: int = 1

    def __post_init__(self) -> None:
        c = tuple(float(x) for x in np.asarray(self.centre, dtype=float).ravel())
        if len(c) != 2 or not all(np.isfinite(c)):
            raise InputError(f"a circle's centre must be two finite numbers (u, v), got {self.centre!r}")
        if not (np.isfinite(self.radius) and self.radius > 0):
            raise InputError(f"a circle's radius must be finite and > 0, got {self.radius!r}")
        if self.sense not in (1, -1):
            raise InputError(f"a circle's sense must be +1 or -1, got {self.sense!r}")
        object.__setattr__(self, "centre", c)
        object.__setattr__(self, "radius", float(self.radius))

    @property
    def signed_area(self) -> float:
        return self.sense * np.pi * self.radius ** 2

    def oriented(self, counter_clockwise: bool) -> "CircleLoop":
        return CircleLoop(self.centre, self.radius, 1 if counter_clockwise else -1)

    def encloses(self, p: ArrayLike) -> NDArray[np.bool_]:
        p = _points(p)
        return np.hypot(p[..., 0] - self.centre[0], p[..., 1] - self.centre[1]) < self.radius

    def distance(self, p: ArrayLike) -> NDArray[np.float64]:
        """``| |p - c| - r |``."""
        p = _points(p)
        return np.abs(np.hypot(p[..., 0] - self.centre[0], p[..., 1] - self.centre[1])
                      - self.radius)

    def bounds(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        c = np.array(self.centre)
        return c - self.radius, c + self.radius


Loop = PolygonLoop | CircleLoop | SplineLoop


def _orient(a: NDArray, b: NDArray, c: NDArray) -> NDArray[np.float64]:
    """``(b - a) × (c - a)``, broadcast."""
    return ((b[..., 0] - a[..., 0]) * (c[..., 1] - a[..., 1])
            - (b[..., 1] - a[..., 1]) * (c[..., 0] - a[..., 0]))


def _segments_cross(a1, b1, a2, b2) -> NDArray[np.bool_]:
    """Whether segments ``a1 b1`` (shape ``(k, 2)``) and ``a2 b2`` (shape ``(l, 2)``) meet,
    as a ``(k, l)`` table (touching counts as meeting). Segments meet only where their
    bounding boxes do: two collinear segments on one line, apart, do not."""
    A1, B1 = a1[:, None], b1[:, None]
    A2, B2 = a2[None], b2[None]
    d1, d2 = _orient(A2, B2, A1), _orient(A2, B2, B1)
    d3, d4 = _orient(A1, B1, A2), _orient(A1, B1, B2)
    boxes = np.all((np.minimum(A1, B1) <= np.maximum(A2, B2))
                   & (np.minimum(A2, B2) <= np.maximum(A1, B1)), axis=-1)
    return (d1 * d2 <= 0) & (d3 * d4 <= 0) & boxes


def _check_simple(loop: PolygonLoop) -> None:
    a, b = loop.segments()
    k = len(a)
    meet = _segments_cross(a, b, a, b)
    i, j = np.triu_indices(k, 2)
    adjacent = (j - i == k - 1)                     # the last edge joins the first
    bad = meet[i, j] & ~adjacent
    if np.any(bad):
        e = int(np.argmax(bad))
        raise InputError(f"polygon loop intersects itself: edge {i[e]} (from {a[i[e]].tolist()}) "
                         f"meets edge {j[e]} (from {a[j[e]].tolist()})")


def loops_cross(first: Loop, second: Loop) -> bool:
    """Whether two loops' curves meet (cross or touch); a spline loop is taken as its
    curve sampled at 64 points per span."""
    if isinstance(first, SplineLoop):
        first = PolygonLoop(first.sample(64))
    if isinstance(second, SplineLoop):
        second = PolygonLoop(second.sample(64))
    if isinstance(first, CircleLoop) and isinstance(second, CircleLoop):
        gap = np.hypot(first.centre[0] - second.centre[0], first.centre[1] - second.centre[1])
        return bool(abs(first.radius - second.radius) <= gap <= first.radius + second.radius)
    if isinstance(first, CircleLoop):
        first, second = second, first
    a, b = first.segments()
    if isinstance(second, PolygonLoop):
        return bool(np.any(_segments_cross(a, b, *second.segments())))
    c = np.array(second.centre)
    near = PolygonLoop.distance(first, c[None])[0]  # nearest point of any edge
    far = np.max(np.hypot(*(np.concatenate([a, b]) - c).T))
    return bool(near <= second.radius <= far)


def _sample_point(loop: Loop) -> NDArray[np.float64]:
    if isinstance(loop, CircleLoop):
        return np.array([loop.centre[0] + loop.radius, loop.centre[1]])
    if isinstance(loop, SplineLoop):
        return loop.sample(1)[0]
    return loop.vertices[0]


@dataclass(frozen=True)
class TrimDomain:
    """A region ``Ω`` = inside of ``outer`` minus the insides of ``holes``.

    Orientation is normalised on construction (outer counter-clockwise, holes clockwise);
    loops that meet, holes outside the outer loop and holes inside holes are refused.

    Examples
    --------
    >>> d = TrimDomain(CircleLoop((0.5, 0.5), 0.4))
    >>> d.contains([[0.5, 0.5], [0.0, 0.0]]).tolist()
    [True, False]
    """

    outer: Loop
    holes: tuple[Loop, ...] = ()
    #: per loop (outer first), the trim edge of each of its spans (polygon segments or
    #: Bézier pieces, as given), or None where the loop is one edge; empty: all are one
    edges: tuple[tuple[int, ...] | None, ...] = ()

    def __post_init__(self) -> None:
        for loop in (self.outer, *self.holes):
            if not isinstance(loop, (PolygonLoop, CircleLoop, SplineLoop)):
                raise InputError("trim loops must be polygons, circles or spline loops, got "
                                 f"{type(loop).__name__}")
        holes = tuple(self.holes)
        given = (self.outer, *holes)
        object.__setattr__(self, "outer", self.outer.oriented(True))
        object.__setattr__(self, "holes", tuple(h.oriented(False) for h in holes))
        object.__setattr__(self, "edges", tuple(
            span_edges(before, after, labels) for before, after, labels in
            zip(given, self.loops, tuple(self.edges) + (None,) * (len(given) - len(self.edges)))))
        loops = self.loops
        for i in range(len(loops)):
            for j in range(i + 1, len(loops)):
                if loops_cross(loops[i], loops[j]):
                    raise InputError(f"trim loops cross: {_name(i)} meets {_name(j)}")
        for k, hole in enumerate(self.holes, start=1):
            if not self.outer.encloses(_sample_point(hole)[None])[0]:
                raise InputError(f"trim loop {_name(k)} lies outside the outer loop")
            for l, other in enumerate(self.holes, start=1):
                if l != k and other.encloses(_sample_point(hole)[None])[0]:
                    raise InputError(f"trim loop {_name(k)} lies inside {_name(l)}")

    @property
    def loops(self) -> tuple[Loop, ...]:
        return (self.outer,) + self.holes

    def contains(self, p: ArrayLike) -> NDArray[np.bool_]:
        """Point-in-domain test, vectorised over points of shape ``S + (2,)``."""
        inside = self.outer.encloses(p)
        for hole in self.holes:
            inside &= ~hole.encloses(p)
        return inside

    def signed_distance(self, p: ArrayLike) -> NDArray[np.float64]:
        """Distance to the nearest loop, positive inside ``Ω``, negative outside."""
        d = np.min([loop.distance(p) for loop in self.loops], axis=0)
        return np.where(self.contains(p), d, -d)

    def area(self) -> float:
        """Exact area ``Σ_loops signed area`` (holes count negatively)."""
        return float(sum(loop.signed_area for loop in self.loops))

    def bounds(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        return self.outer.bounds()

    def edge_count(self, k: int) -> int:
        """How many trim edges loop ``k`` is made of (1 unless :attr:`edges` says more)."""
        labels = self.edges[k] if k < len(self.edges) else None
        return 1 if labels is None else max(labels) + 1


def span_edges(given: Loop, oriented: Loop, labels: tuple[int, ...] | None
               ) -> tuple[int, ...] | None:
    """The trim edge of each span of ``oriented`` from ``labels``, those of the spans of
    ``given`` (the same loop, perhaps run the other way). Reversed, span ``s`` of ``K``
    Bézier pieces is piece ``K - 1 - s``, and segment ``s`` of a polygon of ``K``
    vertices is segment ``K - 2 - s`` (mod ``K``) of the vertices as given."""
    if labels is None:
        return None
    labels = tuple(int(x) for x in labels)
    if not isinstance(given, (PolygonLoop, PiecewiseLoop)):
        raise InputError(f"trim edges are named on polygon and Bézier-piece loops, not on a "
                         f"{type(given).__name__}")
    spans = len(given.vertices) if isinstance(given, PolygonLoop) else given.spans
    if len(labels) != spans or min(labels) < 0:
        raise InputError(f"a loop's trim edges name each of its spans: {spans} spans, got "
                         f"{len(labels)} labels")
    if oriented is given:
        return labels
    K = len(labels)
    if isinstance(given, PolygonLoop):
        return tuple(labels[(K - 2 - s) % K] for s in range(K))
    return labels[::-1]


def _name(k: int) -> str:
    return "the outer loop" if k == 0 else f"hole {k}"
