"""The trim loops of a face in its Brep: 2-D trim curves, their 3-D edges exactly.

A loop of a :class:`~splinedeform.trim.loops.TrimDomain` is ``K`` Bézier pieces ``c_s``
of degree ``m`` in the face's ``(u, v)`` (:func:`splinedeform.cad_trims_3dm.domain_pieces`;
a circle is openNURBS' rational circle, four quarter arcs of degree 2). Piece ``s`` runs
over ``t ∈ [s, s + 1]``; the loop is one trim (or one per trim edge where the domain
labels its spans, :attr:`TrimDomain.edges`), its 2-D curve the clamped NURBS curve of its
pieces (knots of multiplicity ``m`` at the joints).

Its 3-D edge is the trim curve on the surface, ``E(t) = S(c(t))``, exactly: between the
parameters where ``c`` crosses a knot line of the surface (the roots of
``a_u(τ) - k ω(τ)`` for ``c = (a_u, a_v) / ω``), ``S`` is one rational polynomial of
degree ``(p, q)``, and the homogeneous ``ω(τ)^{p+q} (w S, w)(c(τ))`` is a polynomial of
degree ``d = m (p + q)`` in ``τ``. It is interpolated at ``d + 1`` Chebyshev–Lobatto
points of each such interval (exact up to round-off) and the intervals joined into one
rational curve of degree ``d``. The edge's tolerance is the largest distance of ``E``
from ``S(c)`` at points between the interpolation points.

The trims' iso flags follow ``ON_Surface::IsIsoparametric``: a trim whose 2-D control
points lie on a line ``u = const`` (``v = const``) within openNURBS' parameter tolerance
is an iso trim, ``W``/``E`` (``S``/``N``) on the domain's sides, else ``x`` (``y``).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from .cad import NurbsPatch
from .cad_brep_3dm import BOUNDARY, INNER, BrepRecord, _bases, homogeneous, surface_points
from .cad_on_archive import Nurbs
from .trim.bezier import bernstein, bernstein_to_power, lobatto
from .trim.loops import CircleLoop, TrimDomain

Array = NDArray[np.float64]
#: openNURBS' ON_SQRT_EPSILON, ON_EPSILON and ON_ZERO_TOLERANCE (``opennurbs_defines.h``)
SQRT_EPS, EPS, ZERO_TOL = 1.490116119385e-8, 2.2204460492503131e-16, 2.3283064365386963e-10


def loop_pieces(domain: TrimDomain) -> list[tuple[Array, Array]]:
    """Per loop of ``domain`` (outer first) its pieces ``(K, m + 1, 2)`` and their weights
    ``(K, m + 1)`` (1, or a circle's ``1, √½, 1``)."""
    from .cad_trims_3dm import domain_pieces

    out = []
    for loop, pieces in zip(domain.loops, domain_pieces(domain)):
        if pieces is None and isinstance(loop, CircleLoop):
            angles = loop.sense * np.pi / 2 * np.arange(5)
            ends = np.stack([np.cos(angles), np.sin(angles)], -1)
            mid = (ends[:-1] + ends[1:]) / 2 / np.cos(np.pi / 4) ** 2
            unit = np.stack([ends[:-1], mid, ends[1:]], axis=1)
            pieces = np.asarray(loop.centre) + loop.radius * unit
            out.append((pieces, np.tile([1.0, np.sqrt(0.5), 1.0], (4, 1))))
        else:
            out.append((np.asarray(pieces, float), np.ones(np.shape(pieces)[:2])))
    return out


def _crossings(b: Array, w: Array, values: Array, axis: int) -> list[float]:
    """Parameters ``τ ∈ (0, 1)`` where the piece's coordinate ``axis`` equals one of
    ``values``: real roots of ``Σ_a B_a(τ) ω_a (b_a - k)``."""
    M = bernstein_to_power(len(w) - 1)
    out = []
    for k in values:
        coef = M @ (w * (b[:, axis] - k))
        if np.max(np.abs(coef)) <= 1e-14 * max(1.0, abs(k)):
            continue                                   # the piece runs along the knot line
        roots = np.roots(coef[::-1]) if np.any(coef[1:]) else []
        out += [float(r.real) for r in roots if abs(r.imag) <= 1e-12
                and 1e-12 < r.real < 1 - 1e-12]
    return out


def piece_on_surface(b: Array, w: Array, patch: NurbsPatch) -> tuple[list[float], Array]:
    """The exact 3-D image of one rational Bézier piece (module docstring): the interval
    ends ``0 = τ_0 < … < τ_R = 1`` and each interval's homogeneous Bézier points
    ``(R, d + 1, 4)``."""
    bases = _bases(patch)
    H = homogeneous(patch)
    inner = [np.unique(np.asarray(B.knots)[(np.asarray(B.knots) > B.domain[0])
                                           & (np.asarray(B.knots) < B.domain[1])])
             for B in bases]
    cuts = sorted(set([0.0, 1.0] + _crossings(b, w, inner[0], 0) + _crossings(b, w, inner[1], 1)))
    cuts = [c for i, c in enumerate(cuts) if i == 0 or c - cuts[i - 1] > 1e-12]
    m = len(w) - 1
    d = m * (patch.degrees[0] + patch.degrees[1])
    nodes = lobatto(d)
    solve = bernstein(d, nodes)
    out = []
    for t0, t1 in zip(cuts[:-1], cuts[1:]):
        tau = t0 + (t1 - t0) * nodes
        Bm = bernstein(m, tau) * w
        omega = Bm.sum(axis=1)
        uv = (Bm @ b) / omega[:, None]
        centre = bernstein(m, np.array([0.5 * (t0 + t1)]))[0] * w
        h = _surface_homogeneous(bases, H, uv, centre @ b / centre.sum())
        h *= omega[:, None] ** (patch.degrees[0] + patch.degrees[1])
        out.append(np.linalg.solve(solve, h))
    return cuts, np.array(out)


def _surface_homogeneous(bases: Any, H: Array, uv: Array, inside: Array) -> Array:
    """``(w S, w)`` at ``uv`` from the polynomial pieces of the span holding ``inside``
    (the span's own polynomials continued to its ends, where a knot may be C0)."""
    rows = []
    for k, B in enumerate(bases):
        x = uv[:, k]
        t = np.asarray(B.knots)
        n = B.degree
        span = int(np.clip(np.searchsorted(t, inside[k], side="right") - 1, n,
                           len(t) - n - 2))
        rows.append(_span_basis(t, n, span, x))
    Nu, Nv = rows
    return np.einsum("ai,ijc,aj->ac", Nu, H, Nv)


def _span_basis(t: Array, n: int, span: int, x: Array) -> Array:
    """All B-splines at ``x`` as the polynomials of knot span ``[t_span, t_span+1)``
    (the Cox–de Boor triangle of :func:`splinedeform.deboor.triangle` on that span for
    every ``x``, also outside it), shape ``(len(x), N)``."""
    from .deboor import triangle

    k = np.arange(1, n + 1)[:, None]
    left = x[None] - t[span + 1 - k]
    right = t[span + k] - x[None]
    out = np.zeros((len(x), len(t) - n - 1))
    out[:, span - n:span + 1] = triangle(left, right, n, 0)[0].T
    return out


def iso_flag(points: Array, box: Array) -> int:
    """``ON_Surface::IsIsoparametric`` of a 2-D curve with control points ``points``
    (a linear one only: its points on the line between its ends) on the domain ``box``
    ``(u0, u1, v0, v1)``: 0 not iso, 1 x, 2 y, 3 W, 4 S, 5 E, 6 N."""
    lo, hi = points.min(axis=0), points.max(axis=0)
    ds, dt = hi - lo
    s0, s1, t0, t1 = box
    stol, ttol = (s1 - s0) / 32, (t1 - t0) / 32
    if not (ds <= stol or dt <= ttol):
        return 0

    def within(a: float, b: float, c: float, x0: float, x1: float, strict: bool) -> bool:
        dt_ = (b - a) * 8 * SQRT_EPS + (abs(a) + abs(b)) * EPS
        dt_ = min(dt_, 0.5 * (b - a))
        c = min(max(c, a), b)
        return (c - dt_ < x0 if strict else c - dt_ <= x0) and x1 <= c + dt_

    if ds * (t1 - t0) <= dt * (s1 - s0):
        span, lo_k, hi_k, a, b, tol, strict = dt, lo[0], hi[0], s0, s1, stol, False
        flags = (3, 5, 1)
    else:
        span, lo_k, hi_k, a, b, tol, strict = ds, lo[1], hi[1], t0, t1, ttol, True
        flags = (4, 6, 2)
    iso = 0
    if hi_k <= a + tol and within(a, b, a, lo_k, hi_k, strict):
        iso = flags[0]
    elif lo_k >= b - tol and within(a, b, b, lo_k, hi_k, strict):
        iso = flags[1]
    if iso == 0 and within(a, b, 0.5 * (lo_k + hi_k), lo_k, hi_k, strict):
        iso = flags[2]
    if iso == 0:
        return 0
    width = hi_k - lo_k
    tolerance = ZERO_TOL if width < ZERO_TOL and ZERO_TOL * 1024 <= span else width
    return iso if _linear(points, max(tolerance, ZERO_TOL)) else 0


def _linear(points: Array, tolerance: float) -> bool:
    """``ON_NurbsCurve::IsLinear`` for a clamped curve: its control points within
    ``tolerance`` of the line between its ends, projecting into ``[-0.01, 1.01]``."""
    a, b = points[0], points[-1]
    D = b - a
    length2 = float(D @ D)
    if not length2 > 0:
        return False
    t = (points - a) @ D / length2
    if np.any(t < -0.01) or np.any(t > 1.01):
        return False
    return bool(np.all(np.linalg.norm(points - a - t[:, None] * D, axis=1) <= tolerance))


def _joined(pieces: Array, weights: Array) -> Nurbs:
    """One clamped NURBS curve of Bézier pieces over ``t ∈ [0, K]`` (knots of
    multiplicity ``m`` at the joints; a joint's two points are one)."""
    K, m = pieces.shape[0], pieces.shape[1] - 1
    points = np.concatenate([pieces[:, :-1].reshape(-1, pieces.shape[2]), pieces[-1:, -1]])
    w = np.concatenate([weights[:, :-1].ravel(), weights[-1:, -1]])
    knots = np.r_[0.0, np.repeat(np.arange(K + 1.0), m), float(K)]
    return Nurbs((m,), (knots,), points, None if np.all(w == 1.0) else w)


def trim_edge(pieces: Array, weights: Array, patch: NurbsPatch, t0: float
              ) -> tuple[Nurbs, float]:
    """The 3-D edge of a run of pieces (their ``t`` starting at ``t0``), and its
    tolerance (module docstring)."""
    knots, blocks = [t0], []
    for s, (b, w) in enumerate(zip(pieces, weights)):
        cuts, hom = piece_on_surface(b, w, patch)
        for c1, block in zip(cuts[1:], hom):
            if blocks:                                  # the same weight at the joint
                block = block * (blocks[-1][-1, 3] / block[0, 3])
            blocks.append(block)
            knots.append(t0 + s + c1)
    d = blocks[0].shape[0] - 1
    points = np.concatenate([b[:-1] for b in blocks] + [blocks[-1][-1:]])
    full = np.r_[knots[0], np.repeat(knots, d), knots[-1]]
    edge = Nurbs((d,), (full,), points[:, :3] / points[:, 3:], points[:, 3])
    return edge, _edge_gap(edge, pieces, weights, patch, t0)


def _edge_gap(edge: Nurbs, pieces: Array, weights: Array, patch: NurbsPatch,
              t0: float) -> float:
    """The largest distance of ``edge`` from ``S(c(t))`` at 7 points inside each piece."""
    from .cad_brep_3dm import curve_points

    tau = (np.arange(7) + 0.5) / 7
    want = _image(pieces, weights, patch, tau).reshape(-1, 3)
    t = (t0 + np.arange(len(pieces))[:, None] + tau[None]).ravel()
    return float(np.linalg.norm(curve_points(edge, t) - want, axis=1).max())


def add_trim_loops(record: BrepRecord, patch: NurbsPatch, domain: TrimDomain, face: int,
                   outer: int, holes_only: bool = False,
                   joins: dict[int, dict[str, Any]] | None = None, sew: float = 0.0
                   ) -> dict[int, dict[str, Any]]:
    """Append the loops of ``domain`` (the outer one into the face's loop ``outer``, unless
    ``holes_only``: its rectangle's sides are that loop; inner loops after it) with their
    trims, edges and vertices. A loop in ``joins`` (made of one trim) runs along the edge
    given there (:func:`join_edge`) instead of an edge of its own, and so does a loop of
    one trim on a naked closed edge within ``sew`` (:func:`naked_edge_on`). Returns, per
    loop made of one trim with an edge of its own, that edge and its vertex."""
    bu, bv = _bases(patch)
    box = np.array([*bu.domain, *bv.domain])
    joins = dict(joins or {})
    single: dict[int, dict[str, Any]] = {}
    for k, (pieces, weights) in enumerate(loop_pieces(domain)):
        if holes_only and k == 0:
            continue
        if k == 0:
            li = outer
        else:
            li = len(record.loops)
            record.loops.append({"ti": [], "type": INNER, "fi": face})
            record.faces[face]["li"].append(li)
        labels = domain.edges[k] if k < len(domain.edges) and domain.edges[k] else \
            (0,) * len(pieces)
        runs = [0] + [s for s in range(1, len(pieces)) if labels[s] != labels[s - 1]]
        if k not in joins and len(runs) == 1 and sew > 0:
            found = naked_edge_on(record, _image(pieces, weights, patch, TAU_SEW), sew)
            if found is not None:
                joins[k] = found
        if k in joins and len(runs) == 1:
            join_edge(record, patch, pieces, weights, li, box, joins[k])
            continue
        ends = runs + [len(pieces)]
        first = start = _vertex(record, patch, pieces[0, 0])
        for a, b in zip(ends[:-1], ends[1:]):
            end = first if b == len(pieces) else _vertex(record, patch, pieces[b, 0])
            edge, gap = trim_edge(pieces[a:b], weights[a:b], patch, float(a))
            ei, ti = len(record.edges), len(record.trims)
            curve = _joined(pieces[a:b], weights[a:b])
            shifted = Nurbs(curve.degrees, (curve.knots[0] + a,), curve.points, curve.weights)
            record.curves_2d.append(shifted)
            record.curves_3d.append(edge)
            record.edges.append({"c3i": len(record.curves_3d) - 1, "vi": (start, end),
                                 "ti": [ti], "domain": (float(a), float(b)),
                                 "tolerance": gap})
            record.vertices[start]["ei"].append(ei)
            record.vertices[end]["ei"].append(ei)
            record.trims.append({"c2i": len(record.curves_2d) - 1, "ei": ei,
                                 "domain": (float(a), float(b)), "vi": (start, end),
                                 "rev3d": False, "type": BOUNDARY, "li": li,
                                 "iso": iso_flag(curve.points, box)})
            record.loops[li]["ti"].append(ti)
            start = end
        if len(runs) == 1:
            single[k] = {"ei": len(record.edges) - 1, "vertex": first}
    return single


def _image(pieces: Array, weights: Array, patch: NurbsPatch, tau: Array) -> Array:
    """``S(c_s(τ))`` of every piece at ``tau``, shape ``(K, len(tau), 3)``."""
    Bw = bernstein(pieces.shape[1] - 1, tau)[None] * weights[:, None, :]   # (K, q, m + 1)
    uv = np.einsum("kqa,kad->kqd", Bw, pieces) / Bw.sum(axis=2)[..., None]
    return surface_points(patch, uv.reshape(-1, 2)).reshape(len(pieces), len(tau), 3)


#: parameters per piece at which a loop is compared with a naked edge it may lie on
TAU_SEW = np.linspace(0.0, 1.0, 129)


def naked_edge_on(record: BrepRecord, image: Array, sew: float) -> dict[str, Any] | None:
    """A closed edge with one trim (its vertex at both ends) that the closed curve
    ``image`` (its points at :data:`TAU_SEW` on each piece, ``(K, q, 3)``) lies on and
    that lies on it: each's points within ``sew`` of the other's polyline beyond the
    polyline's own chord error (its segments' midpoints from the curve's points at the
    mid parameters); None if there is none."""
    from .cad_brep_3dm import DENSE, curve_domain, curve_points, polyline_distance

    line = np.concatenate([image[:, :-1:2].reshape(-1, 3), image[-1:, -1]])
    mids = image[:, 1::2].reshape(-1, 3)
    own = float(np.linalg.norm(mids - 0.5 * (line[:-1] + line[1:]), axis=1).max())
    for ei, edge in enumerate(record.edges):
        if len(edge["ti"]) != 1 or edge["vi"][0] != edge["vi"][1]:
            continue
        curve = record.curves_3d[edge["c3i"]]
        t = np.linspace(*curve_domain(curve), DENSE)
        dense = curve_points(curve, t)
        chord = float(np.linalg.norm(curve_points(curve, 0.5 * (t[1:] + t[:-1]))
                                     - 0.5 * (dense[1:] + dense[:-1]), axis=1).max())
        if (polyline_distance(line[::8], dense).max() <= sew + chord
                and polyline_distance(dense[::16], line).max() <= sew + own):
            return {"ei": ei, "vertex": edge["vi"][0]}
    return None


def split_piece(b: Array, w: Array, tau: float) -> tuple[tuple[Array, Array], ...]:
    """The two halves ``[0, τ]``, ``[τ, 1]`` of a rational Bézier piece (de Casteljau on
    ``(ω b, ω)``), each as points and weights."""
    Q = np.concatenate([b * w[:, None], w[:, None]], axis=1)
    left, right = [Q[0]], [Q[-1]]
    while len(Q) > 1:
        Q = (1 - tau) * Q[:-1] + tau * Q[1:]
        left.append(Q[0])
        right.append(Q[-1])
    halves = (np.array(left), np.array(right[::-1]))
    return tuple((h[:, :2] / h[:, 2:], h[:, 2]) for h in halves)


def rotate_to(pieces: Array, weights: Array, patch: NurbsPatch, point: Array
              ) -> tuple[Array, Array]:
    """The same closed loop starting where its image ``S(c)`` is nearest ``point``: the
    nearest of 65 samples per piece, refined by ternary search on ``τ`` (to round-off),
    the piece there split in two."""
    tau = np.linspace(0.0, 1.0, 65)
    gap = np.linalg.norm(_image(pieces, weights, patch, tau) - point, axis=-1)
    s, j = np.unravel_index(np.argmin(gap), gap.shape)
    lo, hi = max(tau[j] - 1 / 64, 0.0), min(tau[j] + 1 / 64, 1.0)
    far = lambda t: float(np.linalg.norm(  # noqa: E731
        _image(pieces[s:s + 1], weights[s:s + 1], patch, np.array([t]))[0, 0] - point))
    for _ in range(60):
        m1, m2 = lo + (hi - lo) / 3, hi - (hi - lo) / 3
        lo, hi = (lo, m2) if far(m1) < far(m2) else (m1, hi)
    t = 0.5 * (lo + hi)
    order = list(range(s, len(pieces))) + list(range(s))
    if t <= 1e-12 or t >= 1 - 1e-12:
        if t >= 1 - 1e-12:
            order = order[1:] + order[:1]
        return pieces[order], weights[order]
    (pl, wl), (pr, wr) = split_piece(pieces[s], weights[s], t)
    rest = order[1:]
    return (np.concatenate([pr[None], pieces[rest], pl[None]]),
            np.concatenate([wr[None], weights[rest], wl[None]]))


def join_edge(record: BrepRecord, patch: NurbsPatch, pieces: Array, weights: Array,
              li: int, box: Array, join: dict[str, Any]) -> None:
    """One closed trim of loop ``li`` along the closed edge ``join["ei"]`` that another
    face's loop made: the loop rotated to start at the edge's vertex, ``m_bRev3d`` where
    it runs the other way round in space, the edge's tolerance raised to the largest
    distance of this loop's image from the edge curve."""
    from .cad_brep_3dm import DENSE, curve_domain, curve_points, polyline_distance

    edge = record.edges[join["ei"]]
    own = record.curves_3d[edge["c3i"]]
    vertex = join["vertex"]
    pieces, weights = rotate_to(pieces, weights, patch, record.vertices[vertex]["point"])
    t0, t1 = curve_domain(own)
    dense = curve_points(own, np.linspace(t0, t1, DENSE))
    image = _image(pieces, weights, patch, np.linspace(0.0, 1.0, 9)).reshape(-1, 3)
    edge["tolerance"] = max(edge["tolerance"], float(polyline_distance(image, dense).max()))
    quarter = image[len(image) // 4]                # a quarter way round this loop
    along = np.argmin(np.linalg.norm(dense - quarter, axis=1)) / (DENSE - 1)
    curve = _joined(pieces, weights)
    K = float(len(pieces))
    ti = len(record.trims)
    record.curves_2d.append(curve)
    record.trims.append({"c2i": len(record.curves_2d) - 1, "ei": join["ei"],
                         "domain": (0.0, K), "vi": (vertex, vertex), "rev3d": along > 0.5,
                         "type": BOUNDARY, "li": li, "iso": iso_flag(curve.points, box)})
    edge["ti"].append(ti)
    record.loops[li]["ti"].append(ti)


def _vertex(record: BrepRecord, patch: NurbsPatch, uv: Array) -> int:
    point = surface_points(patch, uv)[0]
    record.vertices.append({"point": point, "ei": [], "tolerance": 0.0})
    return len(record.vertices) - 1
