"""The trim loops of a STEP or IGES face through OpenCASCADE (run in the reader child).

A face's wires are its loops (``BRepTools.OuterWire_s`` the outer one); a wire's edges,
in order (``BRepTools_WireExplorer``), each carry a curve in the face's parameter plane,
its pcurve (``BRep_Tool.CurveOnSurface_s``), run backwards when the edge is reversed in
the wire. Each pcurve is converted to a B-spline (``Geom2dConvert``), whose knots are
where it may lose smoothness, and fitted with Bézier pieces
(:func:`splinedeform.trim.bezier.fit_pieces`): exactly on each knot span when it is
polynomial, within :data:`~splinedeform.cad_trims.FIT_TOL` of the face's parameter box
when rational.

The pieces are in the parameters of the open B-spline surface the reader deforms
(:func:`splinedeform.cad_step_read.open_spline`). Where the face's own surface is that
B-spline (a B-spline surface, a plane; checked at the pcurves' points to
:data:`SAME_TOL`), a pcurve's point ``(u, v)`` is taken as it is, a loop of a periodic
direction moved by whole periods into the opened spline's one period. Elsewhere (a
cylinder, a cone, a sphere … whose B-spline form has another parametrisation) the point
``S(u, v)`` is projected on the spline (``ShapeAnalysis_Surface.ValueOfUV``), a seam's two
candidates ``u`` and ``u ± T`` decided by the nearer to ``(u, v)`` itself, and a degenerate
edge (a pole, whose ``u`` its point does not give) is the segment joining its neighbours;
other points at a pole take the ``u`` of their piece's nearest point.
"""

from __future__ import annotations

import warnings
from pathlib import Path
from typing import Any

import numpy as np

from .cad_step_read import ocp, open_spline, read_faces
from .cad_trims import FIT_TOL, GAP_TOL, fill_singular, pieces_arrays
from .errors import InputError
from .trim.bezier import fit_pieces

#: distance (relative to the face's size) within which the face's surface and its B-spline
#: form give the same point at the same parameters
SAME_TOL = 1e-9


def step_trim_arrays(path: Path, face: int) -> dict[str, Any]:
    """The loops of face ``face`` of a STEP or IGES file as Bézier pieces (see
    :func:`splinedeform.cad_trims.pieces_arrays`)."""
    ocp()
    _, faces, _ = read_faces(path)
    if not 0 <= face < len(faces):
        raise InputError(f"{path}: face {face!r} out of range; the file holds "
                         f"{len(faces)} face(s), numbered 0..{len(faces) - 1}")
    return face_trim_arrays(faces[face], f"{path} face {face}")


def face_trim_arrays(face: Any, source: str) -> dict[str, Any]:
    """One face's loops (outer first) as Bézier pieces in its open spline's parameters."""
    from OCP.BRep import BRep_Tool
    from OCP.BRepTools import BRepTools
    from OCP.TopAbs import TopAbs_WIRE
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")        # the face's reader has said it once
        spline, periodic, _ = open_spline(face, source)
    box = np.array(spline.Bounds(), dtype=float)           # u0, u1, v0, v1
    size = float(np.hypot(box[1] - box[0], box[3] - box[2]))
    mapping = _Mapping(BRep_Tool.Surface_s(face), spline, box, periodic)
    outer = BRepTools.OuterWire_s(face)
    wires = [outer]
    explorer = TopExp_Explorer(face, TopAbs_WIRE)
    while explorer.More():
        wire = (getattr(TopoDS, "Wire", None) or TopoDS.Wire_s)(explorer.Current())
        if not wire.IsSame(outer):
            wires.append(wire)
        explorer.Next()
    loops = []
    for number, wire in enumerate(wires):
        name = f"{source} loop {number} ({'outer' if number == 0 else 'inner'})"
        loops.append(_wire_trims(wire, face, mapping, size, name))
    mapping.check(source)
    return pieces_arrays(loops, box, GAP_TOL * size, source)


def _wire_trims(wire: Any, face: Any, mapping: "_Mapping", size: float, source: str
                ) -> list[np.ndarray]:
    """Bézier pieces of each edge of ``wire``, in wire order and direction."""
    from OCP.BRep import BRep_Tool
    from OCP.BRepTools import BRepTools_WireExplorer
    from OCP.Geom2d import Geom2d_TrimmedCurve
    from OCP.Geom2dConvert import Geom2dConvert
    from OCP.TopAbs import TopAbs_REVERSED

    trims = []
    explorer = BRepTools_WireExplorer(wire, face)
    while explorer.More():
        edge = explorer.Current()
        name = f"{source} edge {len(trims)}"
        first, last = BRep_Tool.Range_s(edge, face)
        curve = BRep_Tool.CurveOnSurface_s(edge, face, first, last)
        if curve is None:
            raise InputError(f"{name}: it has no curve in the face's parameters (pcurve)")
        spline = Geom2dConvert.CurveToBSplineCurve_s(Geom2d_TrimmedCurve(curve, first, last))
        if BRep_Tool.Degenerated_s(edge) and not mapping.same:
            trims.append(None)      # a pole: its u is not defined by its point
            explorer.Next()
            continue
        # the conversion may reparametrise (a circle): its own range and knots
        lo, hi = spline.FirstParameter(), spline.LastParameter()
        knots = [spline.Knot(k) for k in range(1, spline.NbKnots() + 1)]
        breaks = np.unique(np.clip(np.r_[lo, knots, hi], lo, hi))
        if edge.Orientation() == TopAbs_REVERSED:
            breaks = breaks[::-1]
        evaluate = lambda t, c=spline: mapping(  # noqa: E731
            np.array([c.Value(float(x)).Coord() for x in t]))
        degree = spline.Degree() if not spline.IsRational() and mapping.same else 1
        trims.append(fit_pieces(evaluate, breaks, degree, FIT_TOL * size, name))
        explorer.Next()
    return fill_singular(trims, source)


class _Mapping:
    """Face parameters ``(u, v)`` → the open spline's parameters (module docstring)."""

    def __init__(self, surface: Any, spline: Any, box: np.ndarray,
                 periodic: tuple[bool, bool]) -> None:
        from OCP.ShapeAnalysis import ShapeAnalysis_Surface

        self.surface, self.spline, self.box = surface, spline, box
        self.periods = np.array([box[1] - box[0] if periodic[0] else 0.0,
                                 box[3] - box[2] if periodic[1] else 0.0])
        self.analysis = ShapeAnalysis_Surface(spline)
        self.same = surface.DynamicType().Name() in ("Geom_BSplineSurface", "Geom_Plane")
        self.worst = 0.0

    def _into_box(self, uv: np.ndarray) -> np.ndarray:
        """``uv`` (points of one piece) moved by the same whole periods, those that bring
        their mean into the box (a periodic direction only)."""
        lo = self.box[[0, 2]]
        T = np.where(self.periods > 0, self.periods, 1.0)
        offset = (uv.mean(axis=0) - lo) / T
        inside = (offset >= -1e-12) & (offset <= 1 + 1e-12)   # the box's sides included
        shift = np.where((self.periods > 0) & ~inside, np.floor(offset) * T, 0.0)
        return uv - shift

    def __call__(self, uv: np.ndarray) -> np.ndarray:
        from OCP.gp import gp_Pnt

        if self.same:
            mapped = self._into_box(uv)
            for (u, v), (a, b) in zip(uv, mapped):
                p, q = self.surface.Value(float(u), float(v)), self.spline.Value(float(a), float(b))
                self.worst = max(self.worst, p.Distance(q) / (1.0 + p.Distance(gp_Pnt())))
            return mapped
        out, near = [], self._into_box(uv)
        for (u, v), (nu, nv) in zip(uv, near):
            p = self.surface.Value(float(u), float(v))
            best = np.array(self.analysis.ValueOfUV(p, 1e-12 * (1.0 + p.Distance(gp_Pnt())))
                            .Coord())
            for k in (0, 1):                 # a seam: u and u ± T are the same point
                if self.periods[k] > 0:
                    options = best[k] + np.array([-1, 0, 1]) * self.periods[k]
                    best[k] = options[np.argmin(np.abs(options - (nu, nv)[k]))]
            out.append(best)
        return self._poles(np.array(out), uv)

    def _poles(self, mapped: np.ndarray, uv: np.ndarray) -> np.ndarray:
        """Points at a pole (``S_u = 0``: every ``u`` gives the point) take the ``u`` of the
        point of the same piece nearest them in the face's parameters ``uv``; the same in v."""
        from OCP.gp import gp_Pnt, gp_Vec

        derivatives = []
        for a, b in mapped:
            p, du, dv = gp_Pnt(), gp_Vec(), gp_Vec()
            self.spline.D1(float(a), float(b), p, du, dv)
            scale = 1e-9 * (1.0 + p.Distance(gp_Pnt()))
            derivatives.append((du.Magnitude() <= scale, dv.Magnitude() <= scale))
        for k, pole in enumerate(np.array(derivatives).T):
            if np.any(pole) and not np.all(pole):
                good = np.flatnonzero(~pole)
                gap = np.linalg.norm(uv[pole, None] - uv[None, good], axis=-1)
                mapped[pole, k] = mapped[good[np.argmin(gap, axis=1)], k]
        return mapped

    def check(self, source: str) -> None:
        """Refuse if the face's surface and its spline differ at the same parameters by more
        than :data:`SAME_TOL` of the point's distance from the origin (plus one unit)."""
        if self.worst > SAME_TOL:
            raise InputError(f"{source}: its surface and its B-spline form differ by "
                             f"{self.worst:.3g} (relative) at the same parameters; its trims "
                             "cannot be placed on the B-spline")
