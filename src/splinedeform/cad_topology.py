"""The topology of a CAD body from its file: which face edges are shared, free or seams.

The readers (:func:`splinedeform.cad_3dm_read.list_3dm_body`, openNURBS Brep edges and
the trims of every face's loops; :func:`splinedeform.cad_step_edges.list_step_body`,
OpenCASCADE's ``TopExp.MapShapesAndAncestors(shape, EDGE, FACE)``) give each edge of the
file with the faces that use it (a seam: its face twice) and points sampled inside it.
Here each use is placed on a side of its face's parameter rectangle (``u0``, ``u1``,
``v0``, ``v1``): the side whose curve ``S(u_min, v)`` … passes within
:data:`~splinedeform.cad_3dm_read.TRIM_TOL` of the face's size of every sampled point,
the distance measured to the side's chord polygon of
:data:`~splinedeform.cad_3dm_read.TRIM_SAMPLES` points,

.. math:: d(x) = \\min_k \\min_{\\tau \\in [0, 1]} |x - a_k - \\tau (b_k - a_k)|,

and the position ``s = (k + τ) / (S - 1)`` of each point along the side tells which way
the edge runs on it. A use on no side is the trim of a trimmed face (it is counted, not
coupled). Two uses of one edge give an :class:`~splinedeform.body.interface.Interface`,
reversed when the edge runs opposite ways on the two sides, conforming when the two
sides have the same degree, the same knots (each mapped to ``[0, 1]``, mirrored when
reversed) and the same control points and weights along the edge.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Sequence

import numpy as np
from numpy.typing import NDArray

from .body.interface import Interface
from .cad import SEAM_TOL, WEIGHT_TOL, NurbsPatch
from .cad_3dm_read import TRIM_SAMPLES, TRIM_TOL
from .knots import KnotVectorBasis

#: knots along two edges within this distance (on ``[0, 1]``) are the same knot
KNOT_TOL = 1e-9
#: an edge running along less than this fraction of a face's side shares only part of it
#: (a T-junction: the face's side is split among several edges, each another face's side)
WHOLE_SIDE = 0.9
#: the kinds of edges counted, in the order they are reported
EDGE_KINDS = ("shared", "boundary", "seam", "non_manifold", "off_sides")


@dataclass
class Topology:
    """The interfaces of a body and how many edges of each kind it has.

    Attributes
    ----------
    interfaces : list of Interface
        Patch indices are the body's (its faces in the order chosen).
    counts : dict
        ``shared`` (two faces), ``boundary`` (one use), ``seam`` (one face twice),
        ``non_manifold`` (more than two uses), and ``off_sides``: edges with a use that
        lies on no side of its face's rectangle (a trimmed face's loop), not coupled here;
        ``partly_shared`` where some are (also counted ``shared``): edges of two faces that
        run along only part of a side of one (a T-junction), given no interface here, as
        the body couples them along their stretch (:mod:`splinedeform.body.trim_edges`).
    trim_edges : dict
        Of the ``off_sides`` edges: ``shared`` (two faces use it: a body whose faces are
        simulated trimmed couples them along it, :mod:`splinedeform.body.trim_edges`) and
        ``free`` (one face).
    stretches : list of (int, str, int, str)
        Sides of two faces that share only part of their length, found from the geometry
        where the file gives a face no edges (:func:`splinedeform.cad_join.join_loose_faces`):
        ``(a, edge_a, b, edge_b)``, coupled by the body along the stretch.
    trim_joins : list of (int, str, int, str, bool)
        Trim edges of loose trimmed faces found from the geometry along another face's
        trim edge or side (:func:`splinedeform.cad_join_trims.join_loose_trims`):
        ``(a, edge_a, b, edge_b, whole)``, an edge named as a boundary mapping names it
        (``hole1``, ``outer.2``, ``u0``), ``whole`` where the two run along each other's
        whole length; the body couples them along the curve
        (:mod:`splinedeform.body.trimmed`, :mod:`splinedeform.body.trim_edges`).
    """

    interfaces: list[Interface] = field(default_factory=list)
    counts: dict[str, int] = field(default_factory=lambda: dict.fromkeys(EDGE_KINDS, 0))
    trim_edges: dict[str, int] = field(default_factory=lambda: {"shared": 0, "free": 0})
    stretches: list[tuple[int, str, int, str]] = field(default_factory=list)
    trim_joins: list[tuple[int, str, int, str, bool]] = field(default_factory=list)

    def as_dict(self) -> dict[str, Any]:
        """Plain data (for JSON): the counts, one dict per interface and, where there are
        any, one per stretch and one per trim join found from the geometry."""
        out = {**self.counts, "trim_edges": dict(self.trim_edges), "interfaces": [
            {"a": i.a, "edge_a": i.edge_a, "b": i.b, "edge_b": i.edge_b,
             "reversed": i.reversed, "conforming": i.conforming} for i in self.interfaces]}
        if self.stretches:
            out["stretches"] = [{"a": a, "edge_a": ea, "b": b, "edge_b": eb}
                                for a, ea, b, eb in self.stretches]
        if self.trim_joins:
            out["trim_joins"] = [{"a": a, "edge_a": ea, "b": b, "edge_b": eb, "whole": w}
                                 for a, ea, b, eb, w in self.trim_joins]
        return out


def coverage(s: NDArray[np.float64]) -> float:
    """The fraction of a side an edge runs along, from the positions ``s`` on it of the
    edge's points sampled at the middles of ``S`` equal parameter pieces: their range
    widened by half a piece at each end, ``|s_{S-1} − s_0| · S / (S − 1)``."""
    s = np.asarray(s, dtype=float)
    return float(abs(s[-1] - s[0]) * s.size / max(s.size - 1, 1))


def _size(patch: NurbsPatch) -> float:
    """The diagonal of the patch's control net's bounding box."""
    P = np.asarray(patch.points, dtype=float).reshape(-1, 3)
    return max(float(np.linalg.norm(np.ptp(P, axis=0))), 1e-300)


def side_curves(patch: NurbsPatch) -> dict[str, NDArray[np.float64]]:
    """The four sides of the patch's parameter rectangle sampled at
    :data:`~splinedeform.cad_3dm_read.TRIM_SAMPLES` points each, in increasing parameter:
    ``S = (B_u H B_vᵀ)_xyz / (B_u H B_vᵀ)_w`` on the homogeneous net ``H = (w P, w)``, with
    the collocation matrices of the samples built once per direction (their first and
    last rows are the rectangle's sides)."""
    s = np.linspace(0.0, 1.0, TRIM_SAMPLES)
    B = []
    for n, knots in zip(patch.degrees, (patch.knots_u, patch.knots_v)):
        basis = KnotVectorBasis(n, np.asarray(knots, dtype=float))
        lo, hi = basis.domain
        B.append(basis(lo + (hi - lo) * s))
    Bu, Bv = B
    w = np.asarray(patch.weights, dtype=float)
    H = np.concatenate([np.asarray(patch.points, float) * w[..., None], w[..., None]], -1)
    u_sides = np.einsum("ai,ijc,bj->abc", Bu[[0, -1]], H, Bv)        # (2, S, 4)
    v_sides = np.einsum("ai,ijc,bj->bac", Bu, H, Bv[[0, -1]])        # (2, S, 4)
    (u0, u1), (v0, v1) = (sides[..., :3] / sides[..., 3:] for sides in (u_sides, v_sides))
    return {"u0": u0, "u1": u1, "v0": v0, "v1": v1}


def place_on_side(curve: NDArray[np.float64], points: NDArray[np.float64]
                  ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Distance of each point to the chord polygon ``curve`` and its position ``s`` along
    it on ``[0, 1]`` (see the module docstring)."""
    a, ab = curve[:-1], np.diff(curve, axis=0)
    x = np.asarray(points, dtype=float)[:, None, :]
    tau = np.clip(np.einsum("psk,sk->ps", x - a, ab) / np.maximum((ab * ab).sum(-1), 1e-300),
                  0.0, 1.0)
    gap = np.linalg.norm(x - a - tau[..., None] * ab, axis=-1)
    k = gap.argmin(axis=1)
    rows = np.arange(k.size)
    return gap[rows, k], (k + tau[rows, k]) / (curve.shape[0] - 1)


def _along(patch: NurbsPatch, side: str, reverse: bool
           ) -> tuple[int, NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Degree, knots on ``[0, 1]``, control points and weights of the patch along ``side``
    (mirrored when ``reverse``)."""
    axis = 1 if side[0] == "u" else 0           # u0 / u1 run along v
    n = patch.degrees[axis]
    t = np.asarray(patch.knots_v if axis else patch.knots_u, dtype=float)
    t = (t - t[n]) / (t[t.size - n - 1] - t[n])
    row = 0 if side[1] == "0" else -1
    P = np.asarray(patch.points, dtype=float)
    w = np.asarray(patch.weights, dtype=float)
    points, weights = (P[row], w[row]) if axis else (P[:, row], w[:, row])
    if reverse:
        t, points, weights = 1.0 - t[::-1], points[::-1], weights[::-1]
    return n, t, points, weights


def conforming(pa: NurbsPatch, side_a: str, pb: NurbsPatch, side_b: str,
               reversed_: bool) -> bool:
    """Whether two sides are the same B-spline curve on the same knots (module docstring):
    control points within :data:`~splinedeform.cad.SEAM_TOL` of the larger patch's size,
    weights proportional within :data:`~splinedeform.cad.WEIGHT_TOL`."""
    na, ta, Pa, wa = _along(pa, side_a, False)
    nb, tb, Pb, wb = _along(pb, side_b, reversed_)
    if na != nb or ta.size != tb.size or np.abs(ta - tb).max() > KNOT_TOL:
        return False
    size = max(_size(pa), _size(pb))
    wa, wb = wa / wa.max(), wb / wb.max()
    return bool(np.abs(Pa - Pb).max() <= SEAM_TOL * size and
                np.abs(wa - wb).max() <= WEIGHT_TOL * 10)


def body_topology(patches: Sequence[NurbsPatch | None], edges: Sequence[dict[str, Any]],
                  faces: Sequence[int]) -> Topology:
    """The topology of the body made of file faces ``faces`` (see the module docstring).

    Parameters
    ----------
    patches : sequence of NurbsPatch or None
        Every face of the file (None: unreadable, its uses are not placed).
    edges : sequence of dict
        The reader's edges: ``faces`` (file face numbers, one per use) and ``points``.
    faces : sequence of int
        The file faces of the body; patch ``k`` of the body is file face ``faces[k]``.
        Uses on other faces are ignored (an edge shared with one becomes a boundary).
    """
    body = {f: k for k, f in enumerate(faces)}
    sides: dict[int, dict[str, NDArray[np.float64]]] = {}
    topology = Topology()
    for edge in edges:
        uses = [f for f in edge["faces"] if f in body]
        if not uses:
            continue
        kind = ("boundary" if len(uses) == 1 else "non_manifold" if len(uses) > 2
                else "seam" if uses[0] == uses[1] else "shared")
        topology.counts[kind] += 1
        placed: list[tuple[int, str, bool]] = []
        partial = False
        for f in uses:
            patch = patches[f]
            if patch is None:
                continue
            if f not in sides:
                sides[f] = side_curves(patch)
            taken = {side for g, side, _ in placed if g == f}
            tol = TRIM_TOL * _size(patch)
            for side, curve in sides[f].items():
                gap, s = place_on_side(curve, edge["points"])
                if side not in taken and gap.max() <= tol:
                    placed.append((f, side, bool(s[-1] > s[0])))
                    partial |= coverage(s) < WHOLE_SIDE
                    break
        if len(placed) < sum(patches[f] is not None for f in uses):
            topology.counts["off_sides"] += 1
            if kind in ("shared", "boundary"):
                topology.trim_edges["shared" if kind == "shared" else "free"] += 1
        if len(placed) < 2:
            continue
        if partial and kind == "shared":       # a T-junction: coupled along its stretch
            topology.counts["partly_shared"] = topology.counts.get("partly_shared", 0) + 1
            continue
        fa, side_a, forward_a = placed[0]
        for fb, side_b, forward_b in placed[1:]:
            reversed_ = forward_a != forward_b
            topology.interfaces.append(Interface(
                body[fa], side_a, body[fb], side_b, reversed_,
                conforming(patches[fa], side_a, patches[fb], side_b, reversed_)))
    return topology
