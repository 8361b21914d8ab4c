"""A trimmed CAD face run through ``splinedeform run`` on its trimmed region
(scenario/cad_trim.py): a box with a hole through it built by OpenCASCADE, its top face a
square membrane with pinned outer edges and a free hole under a uniform load, against the
same domain given by hand (a built-in plane with ``[surface.trim]``); a .3dm face whose
outer loop runs along the sides of its parameter box."""

import json
import math
import warnings

import numpy as np
import pytest
from typer.testing import CliRunner

from splinedeform import cli
from splinedeform.cad_trims import read_trims

#: the box 4 × 3 × 2 and the holes through it: a circle, and a triangle (a prism)
BOX, CENTRE, RADIUS = (4.0, 3.0, 2.0), (1.5, 1.2), 0.7
TRIANGLE = [(1.1, 0.8), (2.9, 1.3), (1.7, 2.3)]

#: the membrane of the test: cubic, 8 × 6 equal cells of 0.5, pinned outer edges, free hole
COMMON = """
[material]
w10 = 1.0
w01 = 1.0

[boundary]
u0 = "pinned"
u1 = "pinned"
v0 = "pinned"
v1 = "pinned"

[[load]]
kind = "uniform"
force = [0, 0, 1]

[solve]
kind = "static"
frames = 2

[output]
formats = ["report", "obj", "npz"]
resolution = 41
"""

#: the top face of the STEP file, degree 1 on one cell, raised to cubic on 8 × 6 cells
CAD = """
[surface]
shape = "cad"
path = "holed.step"
face = {face}
elevate = [2, 2]
refine = [7, 5]
""" + COMMON

#: the same domain by hand: the rectangle with the hole, on the same cells and degree
HAND = """
[surface]
shape = "plane"
size = [4.0, 3.0]
cells = [8, 6]
degree = 3
knots = "open"
[surface.trim]
rectangle = true
[[surface.trim.loops]]
{hole}
edge = "free"
""" + COMMON


def _holed_step(folder, hole):
    """The box less ``hole`` ("circle" or "triangle") through it, as a STEP file."""
    from OCP.BRepAlgoAPI import BRepAlgoAPI_Cut
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace, BRepBuilderAPI_MakePolygon
    from OCP.BRepPrimAPI import (BRepPrimAPI_MakeBox, BRepPrimAPI_MakeCylinder,
                                 BRepPrimAPI_MakePrism)
    from OCP.gp import gp_Ax2, gp_Dir, gp_Pnt, gp_Vec
    from OCP.STEPControl import STEPControl_AsIs, STEPControl_Writer

    if hole == "circle":
        axis = gp_Ax2(gp_Pnt(*CENTRE, -1.0), gp_Dir(0, 0, 1))
        tool = BRepPrimAPI_MakeCylinder(axis, RADIUS, 4.0).Shape()
    else:
        polygon = BRepBuilderAPI_MakePolygon()
        for x, y in TRIANGLE:
            polygon.Add(gp_Pnt(x, y, -1.0))
        polygon.Close()
        face = BRepBuilderAPI_MakeFace(polygon.Wire()).Face()
        tool = BRepPrimAPI_MakePrism(face, gp_Vec(0, 0, 4.0)).Shape()
    cut = BRepAlgoAPI_Cut(BRepPrimAPI_MakeBox(*BOX).Shape(), tool).Shape()
    path = folder / "holed.step"
    writer = STEPControl_Writer()
    writer.Transfer(cut, STEPControl_AsIs)
    writer.Write(str(path))
    return path


def _top_face(path):
    """The face at z = 2 with one hole (faces with loops [1, 1] are the top and bottom)."""
    from splinedeform.cad_faces import read_faces

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")              # the planes are unbounded surfaces
        listing = read_faces(path)["faces"]
    holed = [f["face"] for f in listing if f["loops"] == [1, 1]]
    assert len(holed) == 2
    return holed


def _run(folder, name, text):
    scenario = folder / f"{name}.toml"
    scenario.write_text(text)
    out = folder / f"{name}_out"
    result = CliRunner().invoke(cli.app, ["run", str(scenario), "-o", str(out), "-q"])
    assert result.exit_code == 0, result.output
    nets = np.load(out / f"{name}_nets.npz")["control_points"]
    vertices = np.array([[float(x) for x in line.split()[1:]]
                         for line in (out / f"{name}.obj").read_text().splitlines()
                         if line.startswith("v ")])
    return result.output, nets[-1] - nets[0], vertices, json.loads(
        (out / "report.json").read_text())


@pytest.fixture(scope="module", params=["circle", "triangle"])
def runs(request, tmp_path_factory):
    """``(hole, CAD run, hand run, the face's TrimDomain)`` of the top face."""
    pytest.importorskip("OCP", reason="the 'cad-step' extra (cadquery-ocp) is not installed")
    folder = tmp_path_factory.mktemp(request.param)
    path = _holed_step(folder, request.param)
    faces = _top_face(path)
    face = faces[0]
    cad = _run(folder, "face", CAD.format(face=face))
    if request.param == "circle":
        hole = f"circle = {{ centre = [{CENTRE[0]}, {CENTRE[1]}], radius = {RADIUS} }}"
    else:
        hole = f"polygon = {[list(p) for p in TRIANGLE]}"
    hand = _run(folder, "hand", HAND.format(hole=hole))
    return request.param, cad, hand, read_trims(path, face)


def test_the_face_runs_on_its_trimmed_region(runs):
    hole, (output, d, vertices, report), _, domain = runs
    # no word of the whole surface: the face is simulated trimmed
    assert "whole underlying surface" not in output
    assert report["solver"]["max displacement"] > 0
    # in-plane coordinates are u, v (the face is the plane z = 2 with x = u, y = v; the
    # load moves z only): every vertex in the box to round-off of the coordinates (1e-12)
    # and outside the hole, where the clipped mesh's crossing points are bisected onto the
    # face's loop to round-off (1e-12); the loop follows the hole's edge within the fit's
    # bound (1e-10 of the box's diagonal, 5)
    u, v = vertices[:, 0], vertices[:, 1]
    assert u.min() > -1e-12 and u.max() < BOX[0] + 1e-12
    assert v.min() > -1e-12 and v.max() < BOX[1] + 1e-12
    assert np.all(domain.signed_distance(vertices[:, :2]) > -1e-12)
    if hole == "circle":
        assert np.hypot(u - CENTRE[0], v - CENTRE[1]).min() > RADIUS - 5e-10
    # the hole is really cut out: vertices reach its edge but none lies well inside
    assert np.all(~domain.holes[0].encloses(vertices[:, :2])
                  | (np.abs(domain.signed_distance(vertices[:, :2])) < 1e-12))


def test_the_face_matches_the_same_domain_given_by_hand(runs):
    hole, (_, d_cad, _, _), (_, d_hand, _, _), _ = runs
    scale = np.abs(d_hand).max()
    error = np.abs(d_cad - d_hand).max() / scale
    if hole == "triangle":
        # the same discrete problem: the same cubic B-splines on the same 8 × 6 cells, the
        # same straight loop pieces (the file's vertices are the triangle's, to round-off),
        # the same quadrature and edge conditions; only round-off differs (1e-10)
        assert error < 1e-10
    else:
        # the same problem up to the cut-cell quadrature along the hole: n + 2 = 5 Gauss
        # points on each piece integrate the exact circle's arcs and the file's Bézier
        # pieces of it with different errors (measured 8.8e-7; with 3 and 8 more points
        # 1.6e-9 and 9e-13, so it is that quadrature alone): 2e-6
        assert error < 2e-6
    assert math.isfinite(scale) and scale > 0.1       # the sag under q = 1 is about 0.8


THREEDM = """
[surface]
shape = "cad"
path = "planes.3dm"
face = 0
elevate = [2, 2]
refine = [5, 3]
{switch}
[material]
w10 = 1.0
w01 = 1.0
{physics}
[[load]]
kind = "uniform"
force = [0, 0, 1]

[solve]
kind = "static"
"""


@pytest.fixture(scope="module")
def trimmed_plane(tmp_path_factory):
    """A .3dm plane trimmed by the polygon (0, 0), (3, 0), (3, 1), (1, 2): its parameter
    box is [0, 3] × [0, 2] and the loop runs along its sides v = 0 and u = 3 (the far
    side)."""
    r3 = pytest.importorskip("rhino3dm", reason="the 'cad' extra (rhino3dm) is not installed")
    model = r3.File3dm()
    corners = [(0, 0), (3, 0), (3, 1), (1, 2), (0, 0)]
    polyline = r3.Polyline([r3.Point3d(x, y, 0.0) for x, y in corners]).ToNurbsCurve()
    model.Objects.AddBrep(r3.Brep.CreateTrimmedPlane(r3.Plane.WorldXY(), polyline))
    folder = tmp_path_factory.mktemp("planes")
    assert model.Write(str(folder / "planes.3dm"), 7)
    return folder


def _built(folder, switch="", physics=""):
    from splinedeform.scenario import build, load_scenario

    path = folder / "plane.toml"
    path.write_text(THREEDM.format(switch=switch, physics=physics))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        built = build(load_scenario(path))
    return built, [str(w.message) for w in caught]


def test_a_loop_along_the_far_side_of_the_box(trimmed_plane):
    built, said = _built(trimmed_plane)
    assert not [s for s in said if "whole underlying surface" in s]
    assert built.surface.trim is not None
    from splinedeform.trim.model_matrices import quadrature_of

    # the model's rule integrates 1 over the polygon: its shoelace area 4, exact for
    # straight pieces on cells (round-off of 100 weights, 1e-12)
    assert quadrature_of(built.surface).weights.sum() == pytest.approx(4.0, rel=1e-12)


def test_a_face_the_trimmed_model_cannot_take(trimmed_plane, monkeypatch):
    # every physics takes a trimmed face now; a face the model cannot hold (here one
    # made so) is taken whole with one warning line, or refused under trimmed = true
    built, said = _built(trimmed_plane, physics='physics = "intrinsic"')
    assert built.surface.trim is not None
    assert not [s for s in said if "whole underlying surface" in s]
    from splinedeform.errors import ScenarioError
    from splinedeform.scenario import cad_trim

    from splinedeform.errors import InputError

    def refused(surface):
        raise InputError("a reason")

    monkeypatch.setattr(cad_trim, "equal_cell_form", refused)
    built, said = _built(trimmed_plane)
    whole = [s for s in said if "whole underlying surface" in s]
    assert len(whole) == 1 and "face 0" in whole[0] and "a reason" in whole[0]
    assert built.surface.trim is None
    with pytest.raises(ScenarioError, match="surface.trimmed"):
        _built(trimmed_plane, switch="trimmed = true")
    built, said = _built(trimmed_plane, switch="trimmed = false")
    assert built.surface.trim is None
    assert not [s for s in said if "whole underlying surface" in s]


def test_the_run_of_a_trimmed_face_writes_trimmed_brep_faces(trimmed_plane, tmp_path):
    """The .3dm of a run on the trimmed plane: every frame one trimmed Brep face, valid
    for openNURBS, whose loop read back from it lies on the model's trim loop."""
    r3 = pytest.importorskip("rhino3dm", reason="the 'cad' extra (rhino3dm) is not installed")
    from splinedeform.cad_trims_3dm import brep_face_trims
    from splinedeform.pipeline import run
    from splinedeform.scenario import load_scenario
    from splinedeform.trim.bezier import evaluate

    path = trimmed_plane / "plane.toml"
    path.write_text(THREEDM.format(switch="", physics="")
                    + 'frames = 2\n[boundary.loops]\nouter = "clamped"\n'
                    '[output]\nformats = ["3dm"]\n')
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = run(load_scenario(path), tmp_path / "out", None)
    loop = result.built.surface.trim.outer
    objects = list(r3.File3dm.Read(str(tmp_path / "out" / "plane.3dm")).Objects)
    assert len(objects) == 3                               # the rest shape and 2 frames
    for obj in objects:
        brep = obj.Geometry
        assert isinstance(brep, r3.Brep) and brep.IsValidWithLog == (True, "")
        (pieces,) = brep_face_trims(brep, brep.Faces[0], obj.Attributes.Name)["loops"]
        x = evaluate(pieces, np.linspace(0.0, 1.0, 9)).reshape(-1, 2)
        # the edges are the loop on the plane (exact), projected back to round-off and
        # fitted by the reader to 1e-10 of the box: on the model's loop to 1e-9
        assert np.abs(loop.distance(x)).max() < 1e-9
