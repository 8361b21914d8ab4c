"""STEP and IGES files read back by OpenCASCADE itself (not splinedeform's reader), and the
measures the tests compare: faces, wires, areas, free edges, outward normals, volume; and
the area of a model's surface over its trimmed region by splinedeform's quadrature."""

from __future__ import annotations

import numpy as np

#: Gauss points per direction of the reference areas: |S_u × S_v| is smooth on each knot
#: cell (not polynomial); 20 points per cell integrate it to round-off here (12 leave
#: 6e-11 on the drilled box's rational wall, 8 leave 9e-8)
AREA_ORDER = 20


def read_shape(path):
    """The shape of a STEP or IGES file as OpenCASCADE's own reader transfers it."""
    from OCP.IFSelect import IFSelect_RetDone
    from OCP.IGESControl import IGESControl_Reader
    from OCP.STEPControl import STEPControl_Reader

    reader = STEPControl_Reader() if str(path).endswith((".step", ".stp")) else IGESControl_Reader()
    assert reader.ReadFile(str(path)) == IFSelect_RetDone
    reader.TransferRoots()
    return reader.OneShape()


def sub_shapes(shape, kind):
    """The sub-shapes of ``shape`` of ``kind`` ("FACE", "WIRE", "EDGE", "SHELL"), in
    explorer order, cast to their type."""
    from OCP import TopAbs
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS

    cast = getattr(TopoDS, kind.capitalize())
    explorer, out = TopExp_Explorer(shape, getattr(TopAbs, f"TopAbs_{kind}")), []
    while explorer.More():
        out.append(cast(explorer.Current()))
        explorer.Next()
    return out


def area(face) -> float:
    """OpenCASCADE's area of a face inside its wires (``BRepGProp``, adaptive, asked for
    1e-12 relative: its default precision leaves 7e-6 on a face bounded by a spline, and
    1e-10 leaves 7e-7 on a rational face where 1e-12 leaves 9e-8)."""
    from OCP.BRepGProp import BRepGProp
    from OCP.GProp import GProp_GProps

    properties = GProp_GProps()
    BRepGProp.SurfaceProperties_s(face, properties, 1e-12)
    return properties.Mass()


def valid(shape) -> bool:
    from OCP.BRepCheck import BRepCheck_Analyzer

    return BRepCheck_Analyzer(shape).IsValid()


def free_edges(shape) -> int:
    """Edges of ``shape`` that bound one face only (``ShapeAnalysis_FreeBounds`` on the
    shape as read, not sewn again)."""
    from OCP.ShapeAnalysis import ShapeAnalysis_FreeBounds

    bounds = ShapeAnalysis_FreeBounds(shape, False, False)
    return sum(len(sub_shapes(w, "EDGE")) for w in (bounds.GetClosedWires(),
                                                     bounds.GetOpenWires()))


def surface_points(face, uv) -> np.ndarray:
    """``S(u, v)`` of the face's surface at parameter points ``uv`` ``(k, 2)``."""
    from OCP.BRep import BRep_Tool

    surface = BRep_Tool.Surface_s(face)
    return np.array([surface.Value(float(u), float(v)).Coord() for u, v in uv])


def outward_normal(face, u: float, v: float) -> np.ndarray:
    """The unit normal of the face at ``(u, v)``: ``S_u × S_v``, negated when the face is
    ``TopAbs_REVERSED`` in its shell."""
    from OCP.BRep import BRep_Tool
    from OCP.gp import gp_Pnt, gp_Vec
    from OCP.TopAbs import TopAbs_REVERSED

    p, du, dv = gp_Pnt(), gp_Vec(), gp_Vec()
    BRep_Tool.Surface_s(face).D1(float(u), float(v), p, du, dv)
    n = np.cross(du.Coord(), dv.Coord())
    n /= np.linalg.norm(n)
    return -n if face.Orientation() == TopAbs_REVERSED else n


def solid_volume(shape) -> float:
    """Volume of the solid bounded by the one shell of ``shape``: positive when its faces'
    normals point outward."""
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeSolid
    from OCP.BRepGProp import BRepGProp
    from OCP.GProp import GProp_GProps

    shell, = sub_shapes(shape, "SHELL")
    properties = GProp_GProps()
    BRepGProp.VolumeProperties_s(BRepBuilderAPI_MakeSolid(shell).Solid(), properties, 1e-12)
    return properties.Mass()


def model_area(surface, net) -> float:
    """``∫_Ω |x_u × x_v| du dv`` of ``surface`` with control net ``net`` over its trimmed
    region (splinedeform's cut-cell quadrature, the rectangle less holes where the outer
    loop is the rectangle), or over its whole rectangle cell by cell (tensor Gauss on the
    spans between its distinct knots) when untrimmed; :data:`AREA_ORDER` points per
    direction."""
    from splinedeform.trim.holed import holed_quadrature
    from splinedeform.trim.quadrature import trim_quadrature
    from splinedeform.trim.surface_trim import holed_rectangle, trim_grid

    moved = surface.with_control_points(net)
    if surface.trim is not None:
        rule = holed_quadrature if holed_rectangle(surface) else trim_quadrature
        quad = rule(surface.trim, trim_grid(surface), AREA_ORDER)
        (_, lu), (_, lv) = surface.domain
        p, w = np.clip(quad.points, 0.0, [lu, lv]), quad.weights
    else:
        xi, om = np.polynomial.legendre.leggauss(AREA_ORDER)
        axes = []
        for basis, (lo, hi) in zip((surface.basis_u, surface.basis_v), surface.domain):
            t = np.unique(np.clip(np.asarray(basis.knots, float), lo, hi))
            a, h = t[:-1, None], (t[1:] - t[:-1])[:, None]
            axes.append(((a + 0.5 * h * (xi + 1)).ravel(), (0.5 * h * om).ravel()))
        (u, wu), (v, wv) = axes
        U, V = np.meshgrid(u, v, indexing="ij")
        p, w = np.stack([U.ravel(), V.ravel()], axis=1), np.outer(wu, wv).ravel()
    du, dv = moved.derivative(p[:, 0], p[:, 1], 1, 0), moved.derivative(p[:, 0], p[:, 1], 0, 1)
    return float(w @ np.linalg.norm(np.cross(du, dv), axis=-1))


def inside_points(surface, count: int = 7) -> np.ndarray:
    """Up to ``count²`` parameter points of a grid over the domain that lie inside the
    trimmed region (all of them for an untrimmed surface)."""
    (u0, u1), (v0, v1) = surface.domain
    s = (np.arange(count) + 0.5) / count
    U, V = np.meshgrid(u0 + s * (u1 - u0), v0 + s * (v1 - v0), indexing="ij")
    uv = np.stack([U.ravel(), V.ravel()], axis=1)
    if surface.trim is None:
        return uv
    from splinedeform.trim.surface_trim import region_contains

    return uv[region_contains(surface, uv)]
