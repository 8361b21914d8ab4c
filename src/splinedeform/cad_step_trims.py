"""Trimmed faces for STEP and IGES files: a trim region as OpenCASCADE wires on its surface.

A face whose surface carries a :class:`~splinedeform.trim.loops.TrimDomain` is written as a
``TopoDS_Face`` on its (deformed) ``Geom_BSplineSurface`` ``S(u, v)`` bounded by one wire
per loop, the outer loop first. Every edge of a wire is a curve ``γ(t)`` in the surface's
parameters, its pcurve, taken exactly as the model holds the loop:

* a polygon: one ``Geom2d_Line`` segment per side, or where the loop names its trim edges
  (:attr:`TrimDomain.edges`, a CAD face's), one degree-1 ``Geom2d_BSplineCurve`` through
  the vertices of each trim edge;
* a circle ``c + r (cos θ, sin θ)``: one closed edge, the ``Geom2d_Circle`` converted to
  its exact rational quadratic B-spline (``Geom2dConvert``), run backwards for a
  clockwise loop: kept as a circle, a clockwise one read back from STEP, and any from
  IGES, bounded an area up to 5e-6 off;
* a closed uniform B-spline ``Σ_k P_k b^n(t - k)``: one closed periodic
  ``Geom2d_BSplineCurve`` on the knots ``0, 1, …, K`` (its pole ``k`` is the B-spline
  supported on ``[k, k + n + 1]``, as in :class:`~splinedeform.trim.spline_loop.SplineLoop`);
* Bézier pieces ``b_{s,a}``: per trim edge (the whole loop where it names none) one
  ``Geom2d_BSplineCurve`` of degree ``n`` whose interior knots ``1, 2, …`` have
  multiplicity ``n``, so that its span ``s`` is piece ``s``.

The loops are oriented as the trimmed region wants them (outer counter-clockwise, holes
clockwise in ``(u, v)``): the region lies on the left of each wire, as OpenCASCADE
requires of a face with ``S_u × S_v`` as its normal. The 3-D curve of each edge,
``S(γ(t))``, is approximated within :data:`CURVE_TOLERANCE` of the patches' size
(``BRepLib.BuildCurves3d_s``); ``ShapeFix_Face`` mends the face only where
``BRepCheck_Analyzer`` finds it invalid. A face marked reversed in its body (orientation
``-1``: its outward normal is ``-(S_u × S_v)``) is written ``TopAbs_REVERSED``.
"""

from __future__ import annotations

from typing import Any, Sequence

import numpy as np
from numpy.typing import NDArray

from .errors import InputError
from .trim.loops import CircleLoop, PolygonLoop, TrimDomain
from .trim.piecewise_loop import PiecewiseLoop
from .trim.spline_loop import SplineLoop

#: the edges' 3-D curves ``S(γ(t))`` follow the surface within this fraction of the size
CURVE_TOLERANCE = 1e-9


def trimmed_face(surface: Any, domain: TrimDomain, size: float) -> Any:
    """The ``TopoDS_Face`` of ``surface`` (a ``Geom_BSplineSurface``) inside the loops of
    ``domain`` (module docstring); ``size`` is the patches' size in the surface's units."""
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace
    from OCP.BRepCheck import BRepCheck_Analyzer
    from OCP.BRepLib import BRepLib
    from OCP.ShapeFix import ShapeFix_Face

    wires = [_wire(loop, _labels(domain, k), surface, f"trim loop {_name(k)}")
             for k, loop in enumerate(domain.loops)]
    made = BRepBuilderAPI_MakeFace(surface, wires[0], True)
    for wire in wires[1:]:
        made.Add(wire)
    if not made.IsDone():
        raise InputError(f"OpenCASCADE could not bound a face by its trim loops "
                         f"({made.Error()})")
    face = made.Face()
    BRepLib.BuildCurves3d_s(face, CURVE_TOLERANCE * size)
    if not BRepCheck_Analyzer(face).IsValid():
        fix = ShapeFix_Face(face)
        fix.Perform()
        face = fix.Face()
        if not BRepCheck_Analyzer(face).IsValid():
            raise InputError("OpenCASCADE finds the face bounded by its trim loops invalid, "
                             "even after ShapeFix_Face")
    return face


def oriented(face: Any, sign: int) -> Any:
    """``face`` as it is (``sign = +1``) or reversed (``-1``: ``TopAbs_REVERSED``)."""
    from OCP.TopoDS import TopoDS

    if sign == 1:
        return face
    return (getattr(TopoDS, "Face", None) or TopoDS.Face_s)(face.Reversed())


def checked_signs(signs: Sequence[int] | None, count: int) -> list[int]:
    """One orientation ``+1`` or ``-1`` per patch (every ``+1`` when None)."""
    if signs is None:
        return [1] * count
    out = list(signs)
    if len(out) != count or any(isinstance(s, bool) or s not in (1, -1) for s in out):
        raise InputError(f"orientation must be one sign, +1 or -1, per patch ({count}), "
                         f"got {out!r}")
    return [int(s) for s in out]


def checked_trims(trims: Sequence[Any] | None, count: int) -> list[TrimDomain | None]:
    """One :class:`TrimDomain` or None per patch (every None when ``trims`` is None)."""
    if trims is None:
        return [None] * count
    out = list(trims)
    if len(out) != count or any(t is not None and not isinstance(t, TrimDomain) for t in out):
        raise InputError(f"trims must be one splinedeform.trim.TrimDomain or None per patch "
                         f"({count}), got {[type(t).__name__ for t in out]}")
    return out


def _name(k: int) -> str:
    return "outer" if k == 0 else f"hole {k}"


def _labels(domain: TrimDomain, k: int) -> tuple[int, ...] | None:
    return domain.edges[k] if k < len(domain.edges) else None


def _wire(loop: Any, labels: tuple[int, ...] | None, surface: Any, source: str) -> Any:
    """The wire of one loop: its edges' pcurves on ``surface``, run along the loop."""
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge, BRepBuilderAPI_MakeWire
    from OCP.TopoDS import TopoDS

    wire = BRepBuilderAPI_MakeWire()
    for curve, first, last, backwards in _curves(loop, labels):
        edge = BRepBuilderAPI_MakeEdge(curve, surface, float(first), float(last))
        if not edge.IsDone():
            raise InputError(f"{source}: OpenCASCADE could not make an edge of its curve "
                             f"({edge.Error()})")
        wire.Add(TopoDS.Edge(edge.Edge().Reversed()) if backwards else edge.Edge())
        if not wire.IsDone():
            raise InputError(f"{source}: its edges do not join into a wire ({wire.Error()})")
    return wire.Wire()


def _curves(loop: Any, labels: tuple[int, ...] | None
            ) -> list[tuple[Any, float, float, bool]]:
    """``(Geom2d curve, first, last, backwards)`` of each edge of ``loop``, in its order;
    ``backwards``: the loop runs the curve from ``last`` to ``first`` (a clockwise circle is
    the counter-clockwise one's edge reversed)."""
    from OCP.Geom2d import Geom2d_Circle, Geom2d_TrimmedCurve
    from OCP.Geom2dConvert import Geom2dConvert
    from OCP.gp import gp_Ax2d, gp_Circ2d, gp_Dir2d, gp_Pnt2d

    if isinstance(loop, CircleLoop):
        axis = gp_Ax2d(gp_Pnt2d(*loop.centre), gp_Dir2d(1.0, 0.0))
        circle = Geom2d_TrimmedCurve(Geom2d_Circle(gp_Circ2d(axis, loop.radius, True)),
                                     0.0, 2 * np.pi)
        spline = Geom2dConvert.CurveToBSplineCurve_s(circle)
        return [(spline, spline.FirstParameter(), spline.LastParameter(), loop.sense < 0)]
    if isinstance(loop, PiecewiseLoop):
        edges = [_bezier_chain(loop.pieces[run]) for run in _runs(labels, loop.spans)]
    elif isinstance(loop, SplineLoop):
        edges = [_periodic(loop.control_points, loop.degree)]
    elif isinstance(loop, PolygonLoop):
        a, b = loop.segments()
        runs = [np.array([k]) for k in range(len(a))] if labels is None else \
            _runs(labels, len(a))
        edges = [_segment(a[run[0]], b[run[0]]) if len(run) == 1 else
                 _bezier_chain(np.stack([a[run], b[run]], axis=1)) for run in runs]
    else:
        raise InputError(f"a trim loop must be a polygon, circle or spline loop, got "
                         f"{type(loop).__name__}")
    return [(*edge, False) for edge in edges]


def _runs(labels: tuple[int, ...] | None, spans: int) -> list[NDArray[np.int64]]:
    """The spans of each trim edge, consecutive (cyclically) and in the loop's order:
    every span one run where ``labels`` is None."""
    if labels is None:
        return [np.arange(spans)]
    labels_ = np.asarray(labels)
    changes = np.flatnonzero(labels_ != np.roll(labels_, 1))
    if changes.size == 0:
        return [np.arange(spans)]
    order = np.roll(np.arange(spans), -int(changes[0]))
    starts = np.flatnonzero(labels_[order] != np.roll(labels_[order], 1))
    return np.split(order, starts[1:])


def _segment(p: NDArray[np.float64], q: NDArray[np.float64]) -> tuple[Any, float, float]:
    """The line from ``p`` through ``q``, parametrised by arc length on ``[0, |q - p|]``."""
    from OCP.Geom2d import Geom2d_Line
    from OCP.gp import gp_Dir2d, gp_Pnt2d

    d = np.asarray(q, float) - np.asarray(p, float)
    return Geom2d_Line(gp_Pnt2d(*map(float, p)), gp_Dir2d(*map(float, d))), 0.0, \
        float(np.hypot(*d))


def _arrays(poles: NDArray[np.float64], knots: NDArray[np.float64],
            mults: NDArray[np.int64]) -> tuple[Any, Any, Any]:
    """OpenCASCADE's arrays of 2-D poles, knots and multiplicities (from index 1)."""
    from OCP.gp import gp_Pnt2d

    try:
        from OCP.OCP.collections import Array1_double as Reals
        from OCP.OCP.collections import Array1_gp_Pnt2d as Points
        from OCP.OCP.collections import Array1_int as Integers
    except ImportError:  # pragma: no cover - older OCP
        from OCP.TColgp import TColgp_Array1OfPnt2d as Points
        from OCP.TColStd import TColStd_Array1OfInteger as Integers
        from OCP.TColStd import TColStd_Array1OfReal as Reals

    P = Points(1, len(poles))
    for k, (x, y) in enumerate(np.asarray(poles, float), start=1):
        P.SetValue(k, gp_Pnt2d(float(x), float(y)))
    T, M = Reals(1, len(knots)), Integers(1, len(knots))
    for k, (t, m) in enumerate(zip(knots, mults), start=1):
        T.SetValue(k, float(t))
        M.SetValue(k, int(m))
    return P, T, M


def _bezier_chain(pieces: NDArray[np.float64]) -> tuple[Any, float, float]:
    """Bézier pieces ``(k, n + 1, 2)`` run one after the other as one B-spline on
    ``[0, k]``: knots ``0 … k``, multiplicity ``n + 1`` at the ends and ``n`` inside."""
    from OCP.Geom2d import Geom2d_BSplineCurve

    k, n = pieces.shape[0], pieces.shape[1] - 1
    poles = np.concatenate([pieces[:, :-1].reshape(-1, 2), pieces[-1:, -1]])
    mults = np.full(k + 1, n)
    mults[[0, -1]] = n + 1
    curve = Geom2d_BSplineCurve(*_arrays(poles, np.arange(k + 1.0), mults), n, False)
    return curve, 0.0, float(k)


def _periodic(points: NDArray[np.float64], degree: int) -> tuple[Any, float, float]:
    """The closed uniform B-spline ``Σ_k P_k b^n(t - k)``, ``t ∈ [0, K)``, as a periodic
    ``Geom2d_BSplineCurve`` (knots ``0 … K``, each simple)."""
    from OCP.Geom2d import Geom2d_BSplineCurve

    K = len(points)
    curve = Geom2d_BSplineCurve(*_arrays(points, np.arange(K + 1.0), np.ones(K + 1, int)),
                                degree, True)
    return curve, 0.0, float(K)
