"""Trim edges of a body's faces and the stretches of them that two faces share.

A trim loop is a chain of trim edges: the file's edges where it names them
(:attr:`~splinedeform.trim.loops.TrimDomain.edges`: OpenCASCADE's edges of a face's
wires, rhino3dm's Brep trims), else the stretches between the loop's corners
(:func:`corner_labels`: a polygon's vertices, or the joints of Bézier pieces, where the
tangent turns by more than :data:`CORNER_SINE`); a circle or a smooth spline loop is one
edge. Each edge is a stretch ``[t_0, t_1]`` of its loop's parameter (spans ``s`` of a
polygon or of Bézier pieces run over ``t ∈ [s, s + 1]``).

Where a solid's faces meet, a trim edge of one lies along an edge of another, in whole or
in part: a trim edge of another trimmed face, or an iso-edge of a face's rectangle (a
boundary edge of the body's iso-edge topology, taken as a stretch of the rectangle's
polygon, :class:`~.interface.TrimEdgeInterface`). Two such edges ``A`` and ``B`` share
the stretches found by closest-point projection
(:meth:`~splinedeform.physics.coupling_curves.CurveSide.closest`) within the body's
tolerance ``tol`` (:func:`common_parts`): ``A``'s parameter is cut at its own ends and at
the projections onto ``A`` of ``B``'s ends that lie within ``tol`` of ``A``; a piece
whose points at :data:`PROBES` fractions all lie within ``tol`` of ``B`` is shared, and
on it ``B``'s parameter runs monotonically between the projections of the piece's ends.
Each shared stretch is coupled by the curve penalties
(:func:`~splinedeform.physics.coupling_curves.curve_line`, :func:`edge_penalty`): the
displacement jump and, with bending, the slope jump across it, factors from the material
and the mesh.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Iterable, Mapping, Sequence

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray

from ..errors import InputError
from ..surface import Surface
from ..trim.loops import PolygonLoop, TrimDomain
from ..trim.model_matrices import loop_names
from ..trim.piecewise_loop import PiecewiseLoop
from ..trim.surface_trim import holed_rectangle
from .interface import EDGES, TrimEdgeInterface
from .topology import Edge

Array = NDArray[np.float64]
ISO_SEGMENTS = {"v0": 0, "u1": 1, "v1": 2, "u0": 3}
"""The segment of the rectangle's counter-clockwise polygon that each iso-edge is."""
CORNER_SINE = 1e-6
"""A loop turns a corner where the sine of its tangent's turn exceeds this (or it turns
back)."""
PROBES = (0.125, 0.25, 0.5, 0.75, 0.875)
"""Fractions of a piece whose points must lie on the other edge for the piece to be shared."""
SAMPLES = 16
"""Samples per edge for the bounding boxes that pick the pairs to project."""


@dataclass(frozen=True)
class EdgeCurve:
    """Edge ``name`` of face ``face``: the stretch ``part`` of the curve ``loop`` (a trim
    loop, or the rectangle's polygon for an iso-edge) in the face's parameters."""

    face: int
    name: str
    loop: Any
    part: tuple[float, float]

    @property
    def trimmed(self) -> bool:
        """Whether it is a trim edge (not an iso-edge)."""
        return self.name not in EDGES


def rectangle(surface: Surface) -> PolygonLoop:
    """The face's parameter rectangle as a counter-clockwise polygon."""
    (_, lu), (_, lv) = surface.domain
    return PolygonLoop(np.array([[0.0, 0.0], [lu, 0.0], [lu, lv], [0.0, lv]]))


def iso_curve(face: int, surface: Surface, edge: str) -> EdgeCurve:
    """Iso-edge ``edge`` as segment :data:`ISO_SEGMENTS` of :func:`rectangle`."""
    k = ISO_SEGMENTS[edge]
    return EdgeCurve(face, edge, rectangle(surface), (float(k), float(k + 1)))


def corner_labels(loop: Any) -> tuple[int, ...] | None:
    """The trim edge of each span of a polygon or Bézier-piece loop, counted from its first
    corner (module docstring); None where it has fewer than two corners or is another
    curve."""
    if isinstance(loop, PolygonLoop):
        start = np.roll(loop.vertices, -1, axis=0) - loop.vertices
        end = np.roll(start, 1, axis=0)
    elif isinstance(loop, PiecewiseLoop):
        pieces = loop.pieces
        start = pieces[:, 1] - pieces[:, 0]
        end = np.roll(pieces[:, -1] - pieces[:, -2], 1, axis=0)
    else:
        return None
    size = np.hypot(*start.T) * np.hypot(*end.T)
    cross = end[:, 0] * start[:, 1] - end[:, 1] * start[:, 0]
    dot = np.einsum("ki,ki->k", end, start)
    corner = (size > 0) & ((np.abs(cross) > CORNER_SINE * size) | (dot < 0))
    if corner.sum() < 2:
        return None
    first = int(np.argmax(corner))
    counted = np.cumsum(np.roll(corner, -first)) - 1
    return tuple(int(x) for x in np.roll(counted, first))


def labelled(surface: Surface) -> Surface:
    """``surface`` with each curve loop that names no trim edges split at its corners
    (:func:`corner_labels`), so that its trim edges have names (``outer.0`` …)."""
    domain = surface.trim
    if domain is None:
        return surface
    first = 1 if holed_rectangle(surface) else 0
    edges = list(domain.edges) + [None] * (len(domain.loops) - len(domain.edges))
    changed = False
    for k, loop in enumerate(domain.loops):
        if k >= first and edges[k] is None:
            edges[k] = corner_labels(loop)
            changed |= edges[k] is not None
    if not changed:
        return surface
    return surface.with_trim(TrimDomain(domain.outer, domain.holes, tuple(edges)))


def trim_edge_curves(face: int, surface: Surface) -> list[EdgeCurve]:
    """The trim edges of a face's curve loops (not the rectangle of a rectangle with
    holes), each a run of spans with one label, named as a boundary mapping names them."""
    from ..physics.coupling_curves import period
    from .trimmed import curve_loops

    out: list[EdgeCurve] = []
    if surface.trim is None:
        return out
    names = loop_names(surface.trim)
    for k in curve_loops(surface):
        loop = surface.trim.loops[k]
        labels = surface.trim.edges[k] if k < len(surface.trim.edges) else None
        if labels is None or max(labels) == 0:
            out.append(EdgeCurve(face, names[k], loop, (0.0, period(loop))))
            continue
        lab = np.asarray(labels)
        starts = np.flatnonzero(lab != np.roll(lab, 1))
        ends = np.append(starts[1:], starts[0] + len(lab))
        for s, e in zip(starts, ends):
            out.append(EdgeCurve(face, f"{names[k]}.{lab[s]}", loop, (float(s), float(e))))
    return out


def edge_curve(patches: Sequence[Surface], face: int, name: str) -> EdgeCurve:
    """Edge ``name`` of face ``face``: an iso-edge or one of :func:`trim_edge_curves`."""
    if not 0 <= face < len(patches):
        raise InputError(f"face {face} is not in the body of {len(patches)} faces")
    if name in EDGES:
        return iso_curve(face, patches[face], name)
    found = [c for c in trim_edge_curves(face, patches[face]) if c.name == name]
    if not found:
        raise InputError(f"face {face} has no trim edge {name!r}")
    return found[0]


def side(patches: Sequence[Surface], curve: EdgeCurve, part: tuple[float, float]) -> Any:
    """The :class:`~splinedeform.physics.coupling_curves.CurveSide` of ``curve`` on the
    stretch ``part`` (any order) of its parameter."""
    from ..physics.coupling_curves import CurveSide

    lo, hi = sorted(part)
    return CurveSide.of_loop(patches[curve.face], curve.loop, (float(lo), float(hi)))


def common_parts(a: Any, b: Any, tol: float) -> list[tuple[tuple[float, float],
                                                              tuple[float, float]]]:
    """The stretches two sides with parts share (module docstring): per stretch ``a``'s
    parameters ``(t_0, t_1)``, increasing, and ``b``'s at those two points, in that order."""
    lo, hi = a.bounds()
    ends_b = b.position(np.array(b.bounds()))[0]
    t = a.closest(ends_b)
    near = np.linalg.norm(a.position(t)[0] - ends_b, axis=1) <= tol
    cuts = np.unique(np.concatenate([[lo, hi], t[near]]))
    cuts = cuts[np.concatenate([[True], np.diff(cuts) > 1e-9 * (hi - lo)])]
    cuts[-1] = hi
    out = []
    blo, bhi = b.bounds()
    for c0, c1 in zip(cuts[:-1], cuts[1:]):
        inner = c0 + (c1 - c0) * np.asarray(PROBES)
        X = a.position(inner)[0]
        s = b.closest(X)
        if np.linalg.norm(b.position(s)[0] - X, axis=1).max() > tol:
            continue
        s0, s1 = b.closest(a.position(np.array([c0, c1]))[0])
        rising = s[-1] >= s[0]
        if (s0 > s[0]) if rising else (s0 < s[0]):      # the other end of a closed edge
            s0 = blo if rising else bhi
        if (s1 < s[-1]) if rising else (s1 > s[-1]):
            s1 = bhi if rising else blo
        if abs(s1 - s0) > 1e-9 * (bhi - blo):
            out.append(((float(c0), float(c1)), (float(s0), float(s1))))
    return out


def find_edge_interfaces(patches: Sequence[Surface], boundary: Iterable[Edge],
                         shared_loops: set[tuple[int, int]], tol: float
                         ) -> tuple[TrimEdgeInterface, ...]:
    """The shared stretches of the faces' trim edges with each other and with the
    ``boundary`` iso-edges (module docstring); loops ``(face, k)`` in ``shared_loops``
    (coupled whole) are left out."""
    whole = {(p, loop_names(patches[p].trim)[k]) for p, k in shared_loops}
    curves = [c for p, s in enumerate(patches) for c in trim_edge_curves(p, s)
              if (p, c.name.split(".")[0]) not in whole]
    curves += [iso_curve(p, patches[p], e) for p, e in boundary]
    if len({c.face for c in curves}) < 2:
        return ()
    sides = [side(patches, c, c.part) for c in curves]
    fractions = np.linspace(0.0, 1.0, SAMPLES + 1)
    boxes, polylines = [], []
    for c, s in zip(curves, sides):
        X = s.position(c.part[0] + fractions * (c.part[1] - c.part[0]))[0]
        margin = tol + 0.1 * float(np.linalg.norm(np.diff(X, axis=0), axis=1).max())
        boxes.append((X.min(axis=0) - margin, X.max(axis=0) + margin))
        polylines.append(X)
    lower, upper = (np.array(x) for x in zip(*boxes))
    overlap = np.all((lower[:, None] <= upper[None]) & (lower[None] <= upper[:, None]), axis=-1)
    found = []
    for i, j in zip(*np.nonzero(np.triu(overlap, 1))):
        a, b = curves[i], curves[j]
        if a.face == b.face or not (a.trimmed or b.trimmed or
                                    _may_share(polylines[i], polylines[j], tol)):
            continue
        for part_a, part_b in common_parts(sides[i], sides[j], tol):
            found.append(TrimEdgeInterface(a.face, a.name, part_a, b.face, b.name, part_b))
    return tuple(found)


def _may_share(a: Array, b: Array, tol: float) -> bool:
    """Whether two edges sampled at :data:`SAMPLES` ``+ 1`` points may share a stretch:
    an inner sample of one lies within ``tol`` plus a quarter of the other's longest chord
    (more than the sag of a chord turning by 90°) of the other's chord polygon. Edges
    that only touch at an end are so told apart without a projection; a stretch shorter
    than a sixteenth of both edges is missed."""
    for x, curve in ((a[1:-1], b), (b[1:-1], a)):
        start, chord = curve[:-1], np.diff(curve, axis=0)
        tau = np.clip(np.einsum("psk,sk->ps", x[:, None] - start, chord)
                      / np.maximum(np.einsum("sk,sk->s", chord, chord), 1e-300), 0.0, 1.0)
        gap = np.linalg.norm(x[:, None] - start - tau[..., None] * chord, axis=-1).min(axis=1)
        if gap.min() <= tol + 0.25 * float(np.linalg.norm(chord, axis=1).max()):
            return True
    return False


def iso_stretches(parts: Sequence[TrimEdgeInterface]) -> list[TrimEdgeInterface]:
    """The stretches shared by two iso-edges (T-junctions of untrimmed rectangles)."""
    return [i for i in parts if i.edge_a in EDGES and i.edge_b in EDGES]


def trim_edge_summary(patches: Sequence[Surface], whole: Sequence[Any],
                      parts: Sequence[TrimEdgeInterface]) -> dict[str, int]:
    """Counts of the trim edges: ``shared`` (coupled to another face in whole or in part,
    whole loops included), ``free`` (the rest) and ``stretches`` (coupled pieces)."""
    every = {(c.face, c.name) for p, s in enumerate(patches) for c in trim_edge_curves(p, s)}
    shared = {(i.a, i.edge_a) for i in parts} | {(i.b, i.edge_b) for i in parts}
    for i in whole:
        for p, k in ((i.a, i.loop_a), (i.b, i.loop_b)):
            name = loop_names(patches[p].trim)[k]
            shared |= {key for key in every if key[0] == p and key[1].split(".")[0] == name}
    shared &= every
    return {"shared": len(shared), "free": len(every - shared),
            "stretches": len(parts) + len(whole)}


RUNS_WITH_POLYGON = {"v0": True, "u1": True, "v1": False, "u0": False}
"""Whether an iso-edge's own parameter increases with the rectangle polygon's."""


def _end_edge(edge: str, at_start: bool) -> str:
    """The edge that an iso-edge meets at its start (``at_start``) or end in the
    rectangle polygon's order (:func:`rectangle`)."""
    from ..physics.coupling_model import ALONG

    first, last = ALONG[edge]
    return first if at_start == RUNS_WITH_POLYGON[edge] else last


def stretch_ends(interface: TrimEdgeInterface, presets: Mapping[Edge, str]) -> tuple[str, str]:
    """The conditions holding a stretch's two ends (in ``a``'s parameter order): at each
    the strongest (:func:`~splinedeform.physics.coupling_model.held`) of the edges that
    meet there, an iso-edge side contributing the edge next to it where the stretch
    reaches that iso-edge's end (a trim edge side, or a stretch ending inside an edge: a
    T-junction's vertex, contributes none)."""
    from ..physics.coupling_model import held

    found: list[list[str | None]] = [[], []]
    for face, name, (p0, p1) in ((interface.a, interface.edge_a, interface.part_a),
                                 (interface.b, interface.edge_b, interface.part_b)):
        if name not in EDGES:
            continue
        k = ISO_SEGMENTS[name]
        for end, p in enumerate((p0, p1)):
            for corner, at_start in ((k, True), (k + 1, False)):
                if abs(p - corner) <= 1e-9:
                    found[end].append(presets.get((face, _end_edge(name, at_start))))
    return held(None, *found[0]), held(None, *found[1])


def stretch_line(patches: Sequence[Surface], interface: TrimEdgeInterface,
                 presets: Mapping[Edge, str] | None = None
                 ) -> tuple[Any, float, sp.csr_matrix]:
    """Both faces' traces on one shared stretch, its element size and its trace space
    (:func:`~splinedeform.physics.coupling_curves.curve_line`, ``b``'s parameter guessed by
    the linear map of the stretch's ends). The trace space is an iso-edge's running basis
    where one side is an iso-edge, the finer one's (more knot-line crossings on the
    stretch) where both are: a T-junction coupled as a non-conforming iso-edge interface,
    the functions at an end that the boundary holds (:func:`stretch_ends` on the edge
    conditions ``presets``, keyed ``(face, edge)``) merged with their neighbours as there
    (:data:`~splinedeform.physics.coupling.HELD`); a held end would otherwise be tied
    twice and lock."""
    from ..physics.coupling import HELD
    from ..physics.coupling_curves import curve_line

    a = side(patches, edge_curve(patches, interface.a, interface.edge_a), interface.part_a)
    b = side(patches, edge_curve(patches, interface.b, interface.edge_b), interface.part_b)
    (c0, c1), (s0, s1) = interface.part_a, interface.part_b
    start = lambda t: s0 + (np.asarray(t) - c0) * ((s1 - s0) / (c1 - c0))  # noqa: E731
    iso = [name in EDGES for name in (interface.edge_a, interface.edge_b)]
    running = None if not any(iso) else 0 if not iso[1] else 1 if not iso[0] else \
        int(len(b.breaks()) > len(a.breaks()))
    line, h = curve_line(a, b, str(interface), start, running)
    if running is None:
        return line, h, line.space(0)
    ends = [HELD[e] for e in stretch_ends(interface, presets or {})]
    name = (interface.edge_a, interface.edge_b)[running]
    along_a = running == 0 or s1 > s0          # its polygon parameter runs with a's
    if RUNS_WITH_POLYGON[name] != along_a:     # its running basis runs against a's
        ends = ends[::-1]
    return line, h, line.space(tuple(ends))


def edge_penalty(patches: Sequence[Surface], interface: TrimEdgeInterface, material: Any,
                 offsets: Sequence[int], presets: Mapping[Edge, str] | None = None
                 ) -> sp.csr_matrix:
    """The penalties of one shared stretch on the line of :func:`stretch_line`, factors
    ``(α, β)`` from the material and the element size: for a plate
    (:class:`~splinedeform.material.Material`)
    :func:`~splinedeform.physics.coupling_curves.line_penalties` on its scalar control
    values; for a Kirchhoff–Love shell (:class:`~splinedeform.physics.shell.ShellMaterial`)
    ``½ α ∫ |Π (d_a − d_b)|² ds + ½ β ∫ (Π (θ_a − θ_b))² ds`` on its interleaved unknowns
    (:func:`~splinedeform.physics.coupling.shell_line_penalty`), ``θ`` the rotation of
    each side's conormal fibre about the tangent, so that a crease keeps its angle."""
    from ..physics import coupling
    from ..physics.coupling_curves import line_penalties
    from ..physics.shell import ShellMaterial

    line, h, space = stretch_line(patches, interface, presets)
    if not isinstance(material, ShellMaterial):
        return line_penalties(line, h, material, interface.a, interface.b, patches, offsets,
                              space)
    alpha, beta = coupling.penalty_factors(material, h)
    size = int(offsets[-1]) + patches[-1].shape[0] * patches[-1].shape[1]
    off_a, off_b = int(offsets[interface.a]), int(offsets[interface.b])
    return coupling.shell_line_penalty(line, (off_a, off_b, size), alpha, beta, space)
