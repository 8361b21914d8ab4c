"""``splinedeform faces``: the objects and faces of .3dm, STEP and IGES files, built here."""

import json
import warnings

import numpy as np
import pytest
from typer.testing import CliRunner

from splinedeform import cli
from splinedeform.cad import NurbsPatch, read_3dm, write_3dm
from splinedeform.cad_faces import read_faces

runner = CliRunner()


def general_patch() -> NurbsPatch:
    """A flat patch on the unit square (a monotone grid, so its area is 1 whatever the
    weights), weights not a product, a C0 line at u = 0.5 (knot repeated twice, degree 2)."""
    knots_u = np.array([0, 0, 0, 0.5, 0.5, 1, 1, 1.0])
    knots_v = np.array([0, 0, 0, 1, 1, 1.0])
    x, y = np.meshgrid([0, 0.2, 0.5, 0.8, 1], [0, 0.5, 1], indexing="ij")
    weights = 1 + 0.5 * np.outer([0, 1, 0, 1, 0], [1, 0, 1]) + 0.25 * np.eye(5, 3)
    return NurbsPatch((2, 2), knots_u, knots_v, np.stack([x, y, 0 * x], -1), weights)


@pytest.fixture(scope="module")
def model_3dm(tmp_path_factory):
    r3 = pytest.importorskip("rhino3dm", reason="the 'cad' extra (rhino3dm) is not installed")
    path = tmp_path_factory.mktemp("faces") / "parts.3dm"
    write_3dm(path, [general_patch()], names=["sheet"], units="m")
    model = r3.File3dm.Read(str(path))
    layer = r3.Layer()
    layer.Name = "walls"
    walls = model.Layers.Add(layer)
    can = r3.ObjectAttributes()
    can.Name, can.LayerIndex = "can", walls
    circle = r3.Circle(r3.Point3d(0, 0, 0), 1.0).ToNurbsCurve()
    model.Objects.AddExtrusion(r3.Extrusion.Create(circle, 2.0, True), can)
    model.Objects.AddBrep(r3.Sphere(r3.Point3d(0, 0, 0), 1.0).ToBrep(), r3.ObjectAttributes())
    assert model.Write(str(path), 7)
    return path


def test_3dm_objects_and_faces(model_3dm):
    with warnings.catch_warnings():
        warnings.simplefilter("error")          # listing warns about nothing
        listing = read_faces(model_3dm)
    assert listing["units"] == "m"
    faces = listing["faces"]
    assert [(f["object"], f["kind"]) for f in faces] == [
        (0, "surface"), (1, "extrusion"), (1, "extrusion"), (1, "extrusion"), (2, "brep")]
    sheet, wall, cap, _, ball = faces
    assert sheet["name"] == "sheet" and wall["name"] == "can" and wall["layer"] == "walls"
    assert sheet["layer"] == ball["layer"] == "Default" and ball["name"] is None
    assert sheet["weights"] == "general" and sheet["c0_knots"] == {"u": [0.5], "v": []}
    assert sheet["degrees"] == [2, 2] and sheet["net"] == [5, 3] and not sheet["trimmed"]
    # a planar map of the unit square: area 1; Gauss quadrature of a rational integrand,
    # 16 points per span, measured 1e-15, asserted to 1e-10
    assert sheet["area"] == pytest.approx(1.0, abs=1e-10)
    # the exact NURBS circle of radius 1 extruded by 2: 4π (quadrature of a smooth rational
    # integrand: round-off, 1e-12 relative)
    assert wall["area"] == pytest.approx(4 * np.pi, rel=1e-12)
    assert wall["closed"] == [True, False] and wall["weights"] == "product"
    assert len(wall["c0_knots"]["u"]) == 3          # four quarter arcs: three C0 joints
    assert cap["trimmed"] and not wall["trimmed"] and cap["degrees"] == [1, 1]
    assert ball["degenerate"] == ["v0", "v1"] and ball["closed"][0]
    # the unit sphere: 4π by the same quadrature
    assert ball["area"] == pytest.approx(4 * np.pi, rel=1e-12)


def test_an_extrusion_is_read_as_its_brep_faces(model_3dm):
    with pytest.warns(UserWarning, match="face 2 is a trimmed Brep face"):
        cap = read_3dm(model_3dm, 2)
    assert cap.degrees == (1, 1)
    wall = read_3dm(model_3dm, 1)
    assert wall.degrees == (2, 1)


def test_the_command_prints_a_table_and_json(model_3dm):
    result = runner.invoke(cli.app, ["faces", str(model_3dm)])
    assert result.exit_code == 0, result.output
    lines = result.output.splitlines()
    assert lines[0].endswith("5 face(s), units m") and lines[1].split()[:3] == [
        "face", "object", "name"]
    assert lines[2].split()[:5] == ["0", "0", "sheet", "Default", "surface"]
    assert "u=0.5" in lines[2] and "general" in lines[2]
    result = runner.invoke(cli.app, ["faces", "--json", str(model_3dm)])
    assert result.exit_code == 0, result.output
    assert [f["face"] for f in json.loads(result.output)["faces"]] == [0, 1, 2, 3, 4]


def test_the_command_refuses_what_is_not_a_cad_file(tmp_path):
    text = tmp_path / "notes.txt"
    text.write_text("no surfaces")
    result = runner.invoke(cli.app, ["faces", str(text)])
    assert result.exit_code == 2 and "not a CAD file" in result.output
    result = runner.invoke(cli.app, ["faces", str(tmp_path / "missing.3dm")])
    assert result.exit_code == 2 and "no such file" in result.output


@pytest.mark.parametrize("suffix", [".step", ".igs"])
def test_step_and_iges_solids_and_their_faces(tmp_path, suffix):
    pytest.importorskip("OCP", reason="the 'cad-step' extra (cadquery-ocp) is not installed")
    from OCP.BRep import BRep_Builder
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox, BRepPrimAPI_MakeCylinder
    from OCP.gp import gp_Pnt
    from OCP.IGESControl import IGESControl_Writer
    from OCP.STEPControl import STEPControl_AsIs, STEPControl_Writer
    from OCP.TopoDS import TopoDS_Compound

    from splinedeform.cad_step_read import ocp

    ocp()    # OpenCASCADE's messages silenced
    both, builder = TopoDS_Compound(), BRep_Builder()
    builder.MakeCompound(both)
    builder.Add(both, BRepPrimAPI_MakeCylinder(1.0, 2.0).Shape())
    builder.Add(both, BRepPrimAPI_MakeBox(gp_Pnt(5, 0, 0), 1.0, 2.0, 3.0).Shape())
    path = tmp_path / f"solids{suffix}"
    if suffix == ".step":
        writer = STEPControl_Writer()
        writer.Transfer(both, STEPControl_AsIs)
        writer.Write(str(path))
    else:
        writer = IGESControl_Writer("MM", 1)
        writer.AddShape(both)
        writer.ComputeModel()
        writer.Write(str(path))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")     # the caps' planes are unbounded (warned)
        faces = read_faces(path)["faces"]
    assert [f["object"] for f in faces] == [0] * 3 + [1] * 6
    assert {f["kind"] for f in faces} == {"solid"}
    wall, cap = faces[0], faces[1]
    # the lateral face of the unit cylinder of height 2: 4π, by our quadrature of the exact
    # NURBS (round-off) and by OpenCASCADE's integration of the face (1e-9 relative)
    assert wall["area"] == pytest.approx(4 * np.pi, rel=1e-12)
    assert wall["trimmed_area"] == pytest.approx(4 * np.pi, rel=1e-9)
    assert wall["periodic"][0] and wall["closed"][0] and not wall["trimmed"]
    assert len(wall["c0_knots"]["u"]) == 2          # three arcs of 120°
    # a disc of radius 1 on the plane's box [-1, 1]²: trimmed, π inside its loop
    assert cap["trimmed"] and cap["area"] == pytest.approx(4.0, rel=1e-12)
    assert cap["trimmed_area"] == pytest.approx(np.pi, rel=1e-9)
    # the box 1 x 2 x 3: faces of areas 6, 6, 3, 3, 2, 2 (exact for bilinear planes)
    assert sorted(f["area"] for f in faces[3:]) == pytest.approx([2, 2, 3, 3, 6, 6], rel=1e-12)
    assert not any(f["trimmed"] for f in faces[3:])


def test_an_unreadable_face_is_listed_with_its_error(tmp_path):
    pytest.importorskip("OCP", reason="the 'cad-step' extra (cadquery-ocp) is not installed")
    from splinedeform.cad_step import write_step

    ring = np.array([[1.0, 0, 0], [1, 1, 0], [0, 1, 0]])
    patch = NurbsPatch((2, 1), np.array([0, 0, 0, 1, 1, 1.0]), np.array([0, 0, 1, 1.0]),
                       np.stack([ring, ring + [0, 0, 2.0]], axis=1),
                       np.outer([1, np.sqrt(0.5), 1], [1, 1]))
    lines = write_step(tmp_path / "good.igs", [patch, patch]).read_text().splitlines(True)
    # the first B-spline entity's weight w10 = √½ (written 0.707106781) becomes -1
    k = next(i for i, line in enumerate(lines) if line[72] == "P" and "0.707106781," in line)
    lines[k] = lines[k][:64].replace("0.707106781,", "-1.00000000,", 1).ljust(64) + lines[k][64:]
    path = tmp_path / "bad.igs"
    path.write_text("".join(lines))
    result = runner.invoke(cli.app, ["faces", "--json", str(path)])
    assert result.exit_code == 0, result.output
    bad, good = json.loads(result.output)["faces"]
    assert "has weight w[1, 0] = -1; NURBS weights must be > 0" in bad["error"]
    assert "error" not in good and good["weights"] == "product"
    # a quarter of the unit cylinder of length 2: π (the file keeps 10 digits)
    assert good["area"] == pytest.approx(np.pi, rel=1e-8)
