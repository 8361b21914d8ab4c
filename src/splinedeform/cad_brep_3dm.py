"""A body of NURBS faces as one openNURBS Brep, with its edges joined where faces meet.

The topology is the body's (:mod:`splinedeform.body.topology`): its interfaces (shared
edges, seams, non-manifold pairs), its poles (edges collapsed to a point) and each face's
orientation. The Brep (:class:`splinedeform.cad_on_archive.BrepRecord`) has

* one **surface** per face (the deformed net), one **face** per surface, reversed where
  the body's orientation is ``-1`` (``m_bRev``: its normal is ``-(S_u × S_v)``);
* one **outer loop** per face: the trims along ``v = v0``, ``u = u1``, ``v = v1``,
  ``u = u0`` in this order, counter-clockwise in ``(u, v)`` as openNURBS wants, each with
  its straight 2-D curve and its iso flag (``S``, ``E``, ``N``, ``W``); a trimmed face
  has instead its trim loops (:mod:`splinedeform.cad_brep_trims`), a rectangle with
  holes its sides and inner loops, and two loops of a trim interface are one edge;
* one **edge** per curve of the body: the sides of faces joined by interfaces are one
  edge (the union of the interfaces' pairs), its 3-D curve the iso curve of the first
  side, ``C(s) = S(u_0, s)`` (its control points ``Q_j = Σ_i N_i(u_0) H_ij`` in
  homogeneous coordinates ``H = (w P, w)``, its knots the surface's along the side);
  every other side is its trim with ``m_bRev3d`` saying whether the trim runs against
  the edge curve (the interface's ``reversed`` and the loop's direction);
* trim types: ``boundary`` (the edge's only trim), ``seam`` (two trims of one loop, a
  closed face's seam), ``mated`` (the others); a pole is a ``singular`` trim, no edge;
* **vertices**: the faces' corners, merged where the interfaces and poles join them
  (the union of their end points, not a distance test); its point is its first corner.

Tolerances are measured, not assumed: an edge's is the largest distance of its other
sides' curves from its own (round-off where the nets were merged, the coupling's gap
where they were not), a vertex's the largest distance of its corners from its point.
A periodic direction (unwrapped by :func:`splinedeform.cad.patch_from_surface`) is a
seam of its face (``u0`` with ``u1``).
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .body.interface import Interface, TrimInterface
from .cad import NurbsPatch
from .cad_on_archive import BrepRecord, Nurbs, brep_bytes, decode
from .errors import InputError, InputWarning
from .knots import KnotVectorBasis

Array = NDArray[np.float64]
Side = tuple[int, str]
#: a face's sides in its outer loop's order; whether the loop runs along each side
#: against its parameter; its corners (i, j) at the side's start and end; its iso flag
LOOP_SIDES = ("v0", "u1", "v1", "u0")
AGAINST = {"v0": False, "u1": False, "v1": True, "u0": True}
CORNERS = {"v0": ((0, 0), (1, 0)), "u1": ((1, 0), (1, 1)), "v1": ((0, 1), (1, 1)),
           "u0": ((0, 0), (0, 1))}
ISO = {"u0": 3, "v0": 4, "u1": 5, "v1": 6}        # ON_Surface::W_iso, S_iso, E_iso, N_iso
BOUNDARY, MATED, SEAM, SINGULAR = 1, 2, 3, 4       # ON_BrepTrim::TYPE
OUTER, INNER = 1, 2                                # ON_BrepLoop::TYPE
#: samples along an edge for its tolerance: each side at this many points, against the
#: edge curve as a polyline of DENSE points
SAMPLES, DENSE = 33, 2049


class BrepError(InputError):
    """The body cannot be written as one Brep (the reason in the message)."""


def patch_nurbs(patch: NurbsPatch) -> Nurbs:
    """The surface record of a patch (rational only where its weights are not all 1)."""
    w = np.asarray(patch.weights, dtype=float)
    return Nurbs(tuple(patch.degrees), (np.asarray(patch.knots_u, float),
                                        np.asarray(patch.knots_v, float)),
                 np.asarray(patch.points, dtype=float),
                 None if np.all(w == 1.0) else w)


def _bases(patch: NurbsPatch) -> tuple[KnotVectorBasis, KnotVectorBasis]:
    return (KnotVectorBasis(patch.degrees[0], np.asarray(patch.knots_u, float)),
            KnotVectorBasis(patch.degrees[1], np.asarray(patch.knots_v, float)))


def homogeneous(patch: NurbsPatch) -> Array:
    """``H_ij = (w_ij P_ij, w_ij)``, shape ``(N_u, N_v, 4)``."""
    w = np.asarray(patch.weights, dtype=float)[..., None]
    return np.concatenate([np.asarray(patch.points, float) * w, w], axis=-1)


def side_curve(patch: NurbsPatch, side: str) -> Nurbs:
    """The iso curve along ``side`` in its increasing parameter (module docstring); where
    the knots are clamped at that end, the first or last row of the net itself."""
    bases, H = _bases(patch), homogeneous(patch)
    axis = 0 if side[0] == "u" else 1
    basis = bases[axis]
    end = int(side[1])
    n, t = basis.degree, np.asarray(basis.knots)
    clamped = np.all(t[:n + 1] == t[0]) if end == 0 else np.all(t[-n - 1:] == t[-1])
    if clamped:
        row = np.take(H, 0 if end == 0 else -1, axis=axis)
    else:
        row = np.tensordot(basis(np.array([basis.domain[end]]))[0], H, axes=([0], [axis]))
    along = bases[1 - axis]
    w = row[:, 3]
    return Nurbs((along.degree,), (np.asarray(along.knots, float),), row[:, :3] / w[:, None],
                 None if np.all(w == 1.0) else w)


def curve_points(curve: Nurbs, s: Array) -> Array:
    """Points ``C(s)`` of a NURBS curve record."""
    basis = KnotVectorBasis(curve.degrees[0], curve.knots[0])
    H = curve.homogeneous() if curve.weights is not None else \
        np.concatenate([curve.points, np.ones((len(curve.points), 1))], axis=1)
    h = basis(np.clip(s, *basis.domain)) @ H
    return h[:, :-1] / h[:, -1:]


def curve_domain(curve: Nurbs) -> tuple[float, float]:
    return KnotVectorBasis(curve.degrees[0], curve.knots[0]).domain


def polyline_distance(x: Array, line: Array) -> Array:
    """Distance of each point ``x`` (m, 3) to the polyline ``line`` (k, 3)."""
    a, d = line[:-1], np.diff(line, axis=0)
    t = np.einsum("mkc,kc->mk", x[:, None] - a[None], d) / np.maximum(
        np.einsum("kc,kc->k", d, d), 1e-300)
    foot = a[None] + np.clip(t, 0.0, 1.0)[..., None] * d[None]
    return np.linalg.norm(x[:, None] - foot, axis=-1).min(axis=1)


class _Union:
    """Union–find over hashable items, each with its parity to its root (a reversal)."""

    def __init__(self) -> None:
        self.parent: dict[Any, tuple[Any, bool]] = {}

    def find(self, x: Any) -> tuple[Any, bool]:
        parent, flip = self.parent.setdefault(x, (x, False))
        if parent == x:
            return x, False
        root, f = self.find(parent)
        self.parent[x] = (root, flip ^ f)
        return root, flip ^ f

    def union(self, a: Any, b: Any, flip: bool = False) -> None:
        (ra, fa), (rb, fb) = self.find(a), self.find(b)
        if ra != rb:
            self.parent[rb] = (ra, fa ^ fb ^ flip)


def surface_points(patch: NurbsPatch, uv: Array) -> Array:
    """``S(u_k, v_k)`` at the points ``uv`` ``(m, 2)``: ``(B_u H B_vᵀ)`` row by row."""
    bu, bv = _bases(patch)
    uv = np.asarray(uv, dtype=float).reshape(-1, 2)
    h = np.einsum("mi,ijc,mj->mc", bu(uv[:, 0]), homogeneous(patch), bv(uv[:, 1]))
    return h[:, :3] / h[:, 3:]


def corner_point(patch: NurbsPatch, corner: tuple[int, int]) -> Array:
    bu, bv = _bases(patch)
    return surface_points(patch, np.array([[bu.domain[corner[0]], bv.domain[corner[1]]]]))[0]


def body_record(patches: Sequence[NurbsPatch], interfaces: Sequence[Interface],
                poles: Sequence[Side], orientation: Sequence[int],
                trims: Sequence[Any] | None = None, holed: Sequence[int] = (),
                trim_interfaces: Sequence[TrimInterface] = (), sew: float = 0.0
                ) -> BrepRecord:
    """The Brep of a body (module docstring); ``trims`` (one per patch, None where
    untrimmed) are the faces' trim domains (:mod:`splinedeform.cad_brep_trims`), those of
    the faces ``holed`` their rectangle less holes (its sides the outer loop, joined by
    the interfaces); two loops of a trim interface, each one trim, are one closed edge,
    and so is a loop of one trim with a naked closed edge it lies on within ``sew``."""
    from .cad_brep_trims import add_trim_loops

    trims = list(trims) if trims is not None else [None] * len(patches)
    if len(trims) != len(patches) or len(orientation) != len(patches):
        raise BrepError(f"{len(patches)} faces need as many orientations and trims, got "
                        f"{len(orientation)} and {len(trims)}")
    named = [(i.a, i.b) for i in (*interfaces, *trim_interfaces)] + [(p, p) for p, _ in poles]
    if any(not 0 <= k < len(patches) for pair in named for k in pair):
        raise BrepError(f"the topology names a face outside the {len(patches)} written")
    whole = [t is None or p in holed for p, t in enumerate(trims)]
    pairs = {}
    for i in trim_interfaces:
        (a, la), (b, lb) = sorted([(i.a, i.loop_a), (i.b, i.loop_b)])
        pairs[(b, lb)] = (a, la)
    built: dict[tuple[int, int], dict[str, Any]] = {}
    pole_set = {(p, e) for p, e in poles if whole[p]}
    sides = _Union()
    corners = _Union()
    for i in interfaces:
        if not (whole[i.a] and whole[i.b]) or (i.a, i.edge_a) in pole_set \
                or (i.b, i.edge_b) in pole_set:
            continue
        sides.union((i.a, i.edge_a), (i.b, i.edge_b), i.reversed)
        ends_a = [(i.a, c) for c in CORNERS[i.edge_a]]
        ends_b = [(i.b, c) for c in CORNERS[i.edge_b]][::-1 if i.reversed else 1]
        for x, y in zip(ends_a, ends_b):
            corners.union(x, y)
    for p, e in pole_set:
        corners.union(*[(p, c) for c in CORNERS[e]])
    record = BrepRecord(surfaces=[patch_nurbs(p) for p in patches])
    vertex_of: dict[Any, int] = {}
    members: dict[int, list[Array]] = {}

    def vertex(p: int, c: tuple[int, int]) -> int:
        root, _ = corners.find((p, c))
        point = corner_point(patches[p], c)
        if root not in vertex_of:
            vertex_of[root] = len(record.vertices)
            record.vertices.append({"point": point, "ei": [], "tolerance": 0.0})
        k = vertex_of[root]
        members.setdefault(k, []).append(point)
        return k

    edge_of: dict[Any, int] = {}
    for p, patch in enumerate(patches):        # the faces, and the sides of the whole ones
        record.faces.append({"li": [len(record.loops)], "si": p, "rev": orientation[p] == -1})
        record.loops.append({"ti": [], "type": OUTER, "fi": p})
        if not whole[p]:
            continue
        li = record.faces[p]["li"][0]
        for side in LOOP_SIDES:
            start, end = (vertex(p, c) for c in CORNERS[side])
            against = AGAINST[side]
            ti = len(record.trims)
            line, domain = _side_line(patch, side)
            trim = {"c2i": len(record.curves_2d), "ei": -1, "iso": ISO[side], "li": li,
                    "vi": (end, start) if against else (start, end), "rev3d": False,
                    "type": SINGULAR, "domain": domain}
            record.curves_2d.append(line)
            if (p, side) not in pole_set:
                root, flip = sides.find((p, side))
                if root not in edge_of:
                    curve = side_curve(patches[root[0]], root[1])
                    edge_of[root] = len(record.edges)
                    first, last = (vertex(root[0], c) for c in CORNERS[root[1]])
                    record.edges.append({"c3i": len(record.curves_3d), "vi": (first, last),
                                         "ti": [], "domain": curve_domain(curve),
                                         "tolerance": 0.0})
                    record.curves_3d.append(curve)
                    record.vertices[first]["ei"].append(edge_of[root])
                    record.vertices[last]["ei"].append(edge_of[root])
                ei = edge_of[root]
                trim.update(ei=ei, rev3d=against ^ flip)
                record.edges[ei]["ti"].append(ti)
                _edge_tolerance(record, ei, side_curve(patch, side))
            record.trims.append(trim)
            record.loops[li]["ti"].append(ti)
    for p, patch in enumerate(patches):        # the trim loops, joined where they meet
        if trims[p] is None:
            continue
        joins = {lb: built[key] for (q, lb), key in pairs.items() if q == p and key in built}
        single = add_trim_loops(record, patch, trims[p], p, record.faces[p]["li"][0],
                                whole[p], joins, sew)
        built.update({(p, k): v for k, v in single.items()})
        unjoined = [f"face {q} loop {k}" for (q, k), key in pairs.items()
                    if q == p and (key not in built
                                   or len(record.edges[built[key]["ei"]]["ti"]) < 2)]
        if unjoined:
            warnings.warn(f"{', '.join(unjoined)} of the body's .3dm Brep are naked edges, "
                          "not joined to the trim loop they meet: a loop of several trims",
                          InputWarning, stacklevel=3)
    _trim_types(record)
    for k, points in members.items():
        record.vertices[k]["tolerance"] = float(np.max(np.linalg.norm(
            np.array(points) - record.vertices[k]["point"], axis=1)))
    return record


def _side_line(patch: NurbsPatch, side: str) -> tuple[Nurbs, tuple[float, float]]:
    """The straight 2-D trim curve of a side, in the loop's direction, and its domain."""
    (u0, u1), (v0, v1) = (b.domain for b in _bases(patch))
    ends = {"v0": ((u0, v0), (u1, v0)), "u1": ((u1, v0), (u1, v1)),
            "v1": ((u1, v1), (u0, v1)), "u0": ((u0, v1), (u0, v0))}[side]
    a, b = (u0, u1) if side[0] == "v" else (v0, v1)
    return Nurbs((1,), (np.array([a, a, b, b]),), np.array(ends, dtype=float)), (a, b)


def _edge_tolerance(record: BrepRecord, ei: int, curve: Nurbs) -> None:
    """Raise edge ``ei``'s tolerance to the distance of ``curve`` (one of its sides) from
    the edge curve (module docstring)."""
    edge = record.edges[ei]
    own = record.curves_3d[edge["c3i"]]
    dense = curve_points(own, np.linspace(*edge["domain"], DENSE))
    x = curve_points(curve, np.linspace(*curve_domain(curve), SAMPLES))
    edge["tolerance"] = max(edge["tolerance"], float(polyline_distance(x, dense).max()))


def _trim_types(record: BrepRecord) -> None:
    """Each edged trim's type: boundary (alone on its edge), seam (another trim of its
    loop on its edge), else mated."""
    for edge in record.edges:
        for ti in edge["ti"]:
            trim = record.trims[ti]
            others = [record.trims[t] for t in edge["ti"] if t != ti]
            trim["type"] = (BOUNDARY if not others else
                            SEAM if any(o["li"] == trim["li"] for o in others) else MATED)


@dataclass(frozen=True)
class BrepTopology:
    """What joins a body's faces in its Brep: interfaces, poles, orientation (one sign per
    face), and the Brep object's name."""

    interfaces: tuple[Interface, ...]
    poles: tuple[Side, ...] = ()
    orientation: tuple[int, ...] | None = None
    name: str = "body"
    #: trimmed faces whose outer loop is their rectangle (its sides joined as untrimmed)
    holed: tuple[int, ...] = ()
    trim_interfaces: tuple[TrimInterface, ...] = ()
    #: distance within which a trim loop lying on a naked closed edge is sewn to it
    sew: float = 0.0

    @classmethod
    def of(cls, body: Any, name: str = "body") -> BrepTopology:
        """The topology of a :class:`~splinedeform.body.Body` (its interfaces, poles and
        trim interfaces, the seam of every periodic direction of a patch, and which of
        its trimmed faces are rectangles with holes)."""
        from .trim.surface_trim import holed_rectangle

        periodic = [tuple(bool(getattr(b, "periodic", False)) for b in (s.basis_u, s.basis_v))
                    for s in body.patches]
        holed = tuple(p for p, s in enumerate(body.patches) if holed_rectangle(s))
        return cls(tuple(body.interfaces) + tuple(seam_interfaces(periodic)),
                   tuple(body.topology.poles), tuple(body.orientation), name, holed,
                   tuple(getattr(body, "trim_interfaces", ())), float(body.topology.tol))


def seam_interfaces(periodic: Sequence[tuple[bool, ...]]) -> list[Interface]:
    """The seam ``u0``–``u1`` (``v0``–``v1``) of every face periodic in ``u`` (``v``)."""
    out = []
    for p, (pu, pv) in enumerate(periodic):
        for flag, a, b in ((pu, "u0", "u1"), (pv, "v0", "v1")):
            if flag:
                out.append(Interface(p, a, p, b, False, True))
    return out


def body_brep(patches: Sequence[NurbsPatch], body: BrepTopology, r3: Any,
              trims: Sequence[Any] | None = None) -> Any:
    """The body as a rhino3dm ``Brep`` (:func:`body_record`, written in the archive form
    and decoded); a :class:`BrepError` naming what openNURBS found where it is not valid."""
    orientation = body.orientation or (1,) * len(patches)
    record = body_record(patches, body.interfaces, body.poles, orientation, trims,
                         body.holed, body.trim_interfaces, body.sew)
    brep = decode(brep_bytes(record), r3)
    if brep is None:
        raise BrepError("openNURBS could not read the Brep written for the body")
    valid, log = brep.IsValidWithLog
    if not valid:
        first = " ".join(str(log).split())[:300]
        raise BrepError(f"openNURBS finds the Brep not valid: {first}")
    return brep
