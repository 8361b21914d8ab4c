"""Trim loops read from CAD files (cad_trims.py, cad_trims_step.py) and written to .3dm:
a box with a cylindrical hole built and written by OpenCASCADE, planar Breps trimmed by a
circle and a polygon built by rhino3dm. Areas against OpenCASCADE's ``BRepGProp`` and
closed forms; loops read back against those written."""

import math
import warnings

import numpy as np
import pytest

from splinedeform import cli
from splinedeform.cad import read_cad, surface_from_patch, write_frames_3dm
from splinedeform.cad_faces import read_faces
from splinedeform.cad_trims import loop_pieces, read_trims
from splinedeform.errors import InputError
from splinedeform.trim import Grid, PiecewiseLoop, PolygonLoop, trim_quadrature

#: the box 4 × 3 × 2 and the hole of radius 0.7 through it
BOX, HOLE_CENTRE, HOLE_RADIUS = (4.0, 3.0, 2.0), (1.5, 1.2), 0.7


def _quiet(function, *args):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")       # "trimmed face: whole surface used"
        return function(*args)


@pytest.fixture(scope="module")
def holed_step(tmp_path_factory):
    """The box minus a cylinder in STEP, NURBS-converted (all faces B-spline surfaces with
    B-spline pcurves) and as OpenCASCADE builds it (planes and a cylinder), and in IGES."""
    pytest.importorskip("OCP", reason="the 'cad-step' extra (cadquery-ocp) is not installed")
    from OCP.BRepAlgoAPI import BRepAlgoAPI_Cut
    from OCP.BRepBuilderAPI import BRepBuilderAPI_NurbsConvert
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox, BRepPrimAPI_MakeCylinder
    from OCP.gp import gp_Ax2, gp_Dir, gp_Pnt
    from OCP.STEPControl import STEPControl_AsIs, STEPControl_Writer

    box = BRepPrimAPI_MakeBox(*BOX).Shape()
    axis = gp_Ax2(gp_Pnt(*HOLE_CENTRE, -1.0), gp_Dir(0, 0, 1))
    cut = BRepAlgoAPI_Cut(box, BRepPrimAPI_MakeCylinder(axis, HOLE_RADIUS, 4.0).Shape()).Shape()
    from OCP.IGESControl import IGESControl_Writer

    folder = tmp_path_factory.mktemp("trims")
    paths = {}
    for name, shape in (("nurbs", BRepBuilderAPI_NurbsConvert(cut, True).Shape()),
                        ("exact", cut)):
        writer = STEPControl_Writer()
        writer.Transfer(shape, STEPControl_AsIs)
        paths[name] = folder / f"holed_{name}.step"
        writer.Write(str(paths[name]))
    writer = IGESControl_Writer("MM", 1)              # 1: faces as BRep entities (186)
    writer.AddShape(cut)
    writer.ComputeModel()
    paths["iges"] = folder / "holed.igs"
    writer.Write(str(paths["iges"]))
    return paths


def _occt_area(path, face):
    """OpenCASCADE's area of the face inside its loops (``BRepGProp``, adaptive to 1e-13)."""
    from OCP.BRepGProp import BRepGProp
    from OCP.GProp import GProp_GProps

    from splinedeform.cad_step_read import read_faces as occt_faces

    properties = GProp_GProps()
    BRepGProp.SurfaceProperties_s(occt_faces(path)[1][face], properties, 1e-13)
    return properties.Mass()


def _jacobian(surface):
    """``|S_u × S_v|`` of a bilinear parallelogram (a plane's NURBS form): constant."""
    P = surface.control_points
    Lu, Lv = surface.basis_u.domain[1], surface.basis_v.domain[1]
    return float(np.linalg.norm(np.cross((P[-1, 0] - P[0, 0]) / Lu, (P[0, -1] - P[0, 0]) / Lv)))


@pytest.mark.parametrize("kind", ["nurbs", "exact", "iges"])
def test_a_step_face_with_a_hole(holed_step, kind):
    path = holed_step[kind]
    listing = _quiet(read_faces, path)["faces"]
    holed = [f["face"] for f in listing if f["loops"] == [1, 1]]
    assert len(holed) == 2                           # the top and the bottom
    for face in holed:
        domain = read_trims(path, face)
        assert isinstance(domain.outer, PolygonLoop) and isinstance(domain.holes[0], PiecewiseLoop)
        surface = _quiet(lambda: surface_from_patch(read_cad(path, face)))
        J = _jacobian(surface)
        Lu, Lv = surface.basis_u.domain[1], surface.basis_v.domain[1]
        # a grid whose lines miss the box's far sides (where the outer loop runs)
        rule = trim_quadrature(domain, Grid((8, 8), (1.06 * Lu, 1.06 * Lv)), 10)
        area = rule.weights.sum() * J
        # planar face, linear parametrisation: the parameter area times J is the area.
        # The hole's pieces are within 1e-10 of the face's box (diagonal 5) of the circle,
        # so the area is off by at most 5e-10 × 4.4 (perimeter): 1e-8 relative holds
        assert area == pytest.approx(_occt_area(path, face), rel=1e-8)
        # against the closed form: the fit's bound as above (measured 3e-14 to 2e-13
        # relative in STEP and IGES: the hole's centre and radius are round numbers)
        closed = BOX[0] * BOX[1] - math.pi * HOLE_RADIUS ** 2
        assert area == pytest.approx(closed, rel=1e-9)
        assert domain.area() == pytest.approx(rule.weights.sum(), rel=1e-12)  # two exact rules
        # the listing's fraction is that area over the parameter box (same rule, other grid)
        fraction = listing[face]["trimmed_fraction"]
        assert fraction == pytest.approx(domain.area() / (Lu * Lv), rel=1e-12)
        assert listing[face]["trimmed"]


@pytest.mark.parametrize("kind", ["nurbs", "exact", "iges"])
def test_an_untrimmed_face_is_its_parameter_rectangle(holed_step, kind):
    path = holed_step[kind]
    listing = _quiet(read_faces, path)["faces"]
    plain = [f["face"] for f in listing if f["loops"] == [1, 0]]
    assert len(plain) == 5                           # four sides and the hole's wall
    for face in plain:
        domain = read_trims(path, face)
        surface = _quiet(lambda: surface_from_patch(read_cad(path, face)))
        Lu, Lv = surface.basis_u.domain[1], surface.basis_v.domain[1]
        assert isinstance(domain.outer, PolygonLoop) and not domain.holes
        corners = {(0.0, 0.0), (Lu, 0.0), (Lu, Lv), (0.0, Lv)}
        vertices = domain.outer.vertices
        # the pcurves are straight lines through the corners: the corners to round-off
        # of the parameters (values up to 2π: 1e-12), collinear midpoints allowed
        for corner in corners:
            assert np.min(np.hypot(*(vertices - corner).T)) < 1e-12
        assert domain.area() == pytest.approx(Lu * Lv, rel=1e-12)
        assert listing[face]["trimmed_fraction"] == pytest.approx(1.0, rel=1e-12)


@pytest.fixture(scope="module")
def trimmed_planes(tmp_path_factory):
    """A disc (a plane trimmed by the NURBS circle) and a plane trimmed by a polygon."""
    r3 = pytest.importorskip("rhino3dm", reason="the 'cad' extra (rhino3dm) is not installed")
    model = r3.File3dm()
    circle = r3.NurbsCurve.CreateFromCircle(r3.Circle(r3.Point3d(1.0, 2.0, 0.0), 0.75))
    model.Objects.AddBrep(r3.Brep.CreateTrimmedPlane(r3.Plane.WorldXY(), circle))
    corners = [(0, 0), (3, 0), (3, 1), (1, 2), (0, 0)]
    polyline = r3.Polyline([r3.Point3d(x, y, 0.0) for x, y in corners]).ToNurbsCurve()
    model.Objects.AddBrep(r3.Brep.CreateTrimmedPlane(r3.Plane.WorldXY(), polyline))
    path = tmp_path_factory.mktemp("trims") / "planes.3dm"
    assert model.Write(str(path), 7)
    return path


def test_3dm_brep_faces_trimmed_by_a_circle_and_a_polygon(trimmed_planes):
    disc = read_trims(trimmed_planes, 0)
    surface = surface_from_patch(_quiet(read_cad, trimmed_planes, 0))
    assert _jacobian(surface) == pytest.approx(1.0, rel=1e-14)   # the XY plane, unscaled
    # the edge (a rational circle) pulled back onto the plane exactly, fitted within 1e-10
    # of the box (diagonal 2.1): area within 1e-10 × 2.1 × 4.7 (perimeter) of π r²
    assert disc.area() == pytest.approx(math.pi * 0.75 ** 2, abs=1e-9)
    lo, hi = disc.bounds()
    # the face's box is the circle's: the loop touches all four sides, inside the box
    assert lo.min() >= 0 and np.all(hi <= [1.5, 1.5])
    polygon = read_trims(trimmed_planes, 1)
    assert isinstance(polygon.outer, PolygonLoop)
    # straight edges pulled back exactly (projection on a plane: round-off, 1e-12)
    want = np.array([(0, 0), (3, 0), (3, 1), (1, 2)], dtype=float)
    got = polygon.outer.vertices
    assert all(np.min(np.hypot(*(got - w).T)) < 1e-12 for w in want)
    assert polygon.area() == pytest.approx(4.0, rel=1e-12)        # shoelace of the corners


def test_3dm_export_keeps_the_trim_loops(trimmed_planes, tmp_path):
    import rhino3dm as r3

    from splinedeform.trim import bezier

    domain = read_trims(trimmed_planes, 0)
    surface = surface_from_patch(_quiet(read_cad, trimmed_planes, 0))
    nets = np.stack([surface.control_points, 1.1 * surface.control_points])
    path = write_frames_3dm(tmp_path / "frames.3dm", surface, np.array([0.0, 1.0]), nets,
                            trim=domain)
    model = r3.File3dm.Read(str(path))
    objects = list(model.Objects)
    # each frame one trimmed Brep face, valid for openNURBS, its loop an outer loop
    assert [o.Attributes.Name for o in objects] == ["initial", "frame 0: t = 0",
                                                   "frame 1: t = 1"]
    for obj in objects:
        brep = obj.Geometry
        assert isinstance(brep, r3.Brep) and brep.IsValidWithLog == (True, "")
        assert [str(lp.LoopType).split(".")[-1] for lp in brep.Faces[0].Loops] == ["Outer"]
    for face in range(3):                            # and read as loops again
        again = read_trims(path, face)
        x = bezier.evaluate(loop_pieces(again.outer), np.linspace(0, 1, 9)).reshape(-1, 2)
        # on the written loop: its edge S(c(t)) is exact on the plane, projected back to
        # round-off, fitted to 1e-10 of the box by the reader
        assert np.abs(domain.outer.distance(x)).max() < 1e-9
        assert again.area() == pytest.approx(domain.area(), rel=1e-9)


def test_the_listing_shows_loops(trimmed_planes):
    result = __import__("typer.testing", fromlist=["CliRunner"]).CliRunner().invoke(
        cli.app, ["faces", str(trimmed_planes)])
    assert result.exit_code == 0, result.output
    header, disc, polygon = result.output.splitlines()[1:4]
    assert header.split()[-2:] == ["loops", "inside"]
    # π/4 of the disc's box, 4/6 of the polygon's, shown to 4 digits
    assert disc.split()[-2:] == ["1+0", "78.54%"] and polygon.split()[-2:] == ["1+0", "66.67%"]


def test_bad_requests_are_refused(trimmed_planes, tmp_path):
    with pytest.raises(InputError, match="face 7 out of range"):
        read_trims(trimmed_planes, 7)
    with pytest.raises(InputError, match="not a CAD file"):
        read_trims(tmp_path / "loops.txt", 0)


def test_3dm_closed_surfaces_seams_and_poles(tmp_path):
    r3 = pytest.importorskip("rhino3dm", reason="the 'cad' extra (rhino3dm) is not installed")
    model = r3.File3dm()
    circle = r3.Circle(r3.Point3d(0, 0, 0), 1.0).ToNurbsCurve()
    model.Objects.AddExtrusion(r3.Extrusion.Create(circle, 2.0, True), r3.ObjectAttributes())
    model.Objects.AddBrep(r3.Sphere(r3.Point3d(0, 0, 0), 1.0).ToBrep(), r3.ObjectAttributes())
    path = tmp_path / "closed.3dm"
    assert model.Write(str(path), 7)
    listing = _quiet(read_faces, path)["faces"]
    wall, cap, _, ball = listing
    # the tube's wall and the sphere: loops along the seam (both sides) and, for the
    # sphere, singular trims at the poles: the whole parameter rectangle (straight
    # pieces: the corners to round-off)
    for face in (0, 3):
        domain = read_trims(path, face)
        surface = _quiet(lambda: surface_from_patch(read_cad(path, face)))
        Lu, Lv = surface.basis_u.domain[1], surface.basis_v.domain[1]
        assert isinstance(domain.outer, PolygonLoop)
        assert domain.area() == pytest.approx(Lu * Lv, rel=1e-12)
        assert listing[face]["trimmed_fraction"] == pytest.approx(1.0, rel=1e-12)
    # a cap: the unit disc in its 2.5 × 2.5 plane (the fit's 1e-10 of the box, as above)
    assert cap["loops"] == [1, 0] and cap["area"] == pytest.approx(6.25, rel=1e-12)
    assert cap["trimmed_fraction"] == pytest.approx(math.pi / 6.25, abs=1e-9)
    assert wall["loops"] == ball["loops"] == [1, 0]


def test_step_sphere_and_cone_seams_and_poles(tmp_path):
    pytest.importorskip("OCP", reason="the 'cad-step' extra (cadquery-ocp) is not installed")
    from OCP.BRep import BRep_Builder
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeCone, BRepPrimAPI_MakeSphere
    from OCP.gp import gp_Ax2, gp_Dir, gp_Pnt
    from OCP.STEPControl import STEPControl_AsIs, STEPControl_Writer
    from OCP.TopoDS import TopoDS_Compound

    builder, compound = BRep_Builder(), TopoDS_Compound()
    builder.MakeCompound(compound)
    builder.Add(compound, BRepPrimAPI_MakeSphere(1.0).Shape())
    axis = gp_Ax2(gp_Pnt(3, 0, 0), gp_Dir(0, 0, 1))
    builder.Add(compound, BRepPrimAPI_MakeCone(axis, 1.0, 0.0, 2.0).Shape())
    writer = STEPControl_Writer()
    writer.Transfer(compound, STEPControl_AsIs)
    path = tmp_path / "round.step"
    writer.Write(str(path))
    sphere, cone, cap = _quiet(read_faces, path)["faces"]
    # a sphere and a cone, whose B-spline forms have other parametrisations than their
    # own (points projected): seams on both sides, poles at the tips. Their loops are the
    # whole parameter rectangles (straight pieces, the fraction to round-off)
    assert sphere["loops"] == cone["loops"] == [1, 0]
    assert sphere["trimmed_fraction"] == pytest.approx(1.0, rel=1e-12)
    assert cone["trimmed_fraction"] == pytest.approx(1.0, rel=1e-12)
    # the cone's base: the unit disc on its 2 × 2 plane, to the fit's bound (see above)
    assert cap["trimmed_fraction"] == pytest.approx(math.pi / 4, abs=1e-9)
    assert cap["trimmed_area"] == pytest.approx(math.pi, rel=1e-12)   # OpenCASCADE's
