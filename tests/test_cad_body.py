"""Whole CAD bodies read with the file's topology (``read_body``), built here with rhino3dm
and OpenCASCADE: a box of 6 faces, a capped cylinder, a sphere."""

import json
import warnings

import numpy as np
import pytest
from typer.testing import CliRunner

from splinedeform import cli
from splinedeform.cad import patch_from_surface
from splinedeform.errors import InputError

r3 = pytest.importorskip("rhino3dm", reason="the 'cad' extra (rhino3dm) is not installed")

from splinedeform.cad_body import read_body  # noqa: E402
from splinedeform.cad_topology import side_curves  # noqa: E402

runner = CliRunner()


@pytest.fixture(scope="module")
def solids_3dm(tmp_path_factory):
    """A 1 × 2 × 3 box (object "box"), a capped cylinder of radius 1 and height 2 (object
    "can" on layer "walls") and a unit sphere, in inches."""
    path = tmp_path_factory.mktemp("body") / "solids.3dm"
    model = r3.File3dm()
    model.Settings.ModelUnitSystem = r3.UnitSystem.Inches
    for name in ("Default", "walls"):          # objects are on layer 0 unless told
        layer = r3.Layer()
        layer.Name = name
        walls = model.Layers.Add(layer)
    box, can = r3.ObjectAttributes(), r3.ObjectAttributes()
    box.Name, can.Name, can.LayerIndex = "box", "can", walls
    model.Objects.AddBrep(r3.Brep.CreateFromBox(r3.Box(r3.BoundingBox(0, 0, 0, 1, 2, 3))), box)
    cylinder = r3.Cylinder(r3.Circle(r3.Point3d(5, 0, 0), 1.0), 2.0)
    model.Objects.AddBrep(r3.Brep.CreateFromCylinder(cylinder, True, True), can)
    sphere = r3.ObjectAttributes()
    sphere.Name = "ball"
    model.Objects.AddBrep(r3.Brep.CreateFromSphere(r3.Sphere(r3.Point3d(0, 9, 0), 1.0)), sphere)
    assert model.Write(str(path), 7)
    return path


def assert_interfaces_meet(surfaces, topology):
    """Each interface's two sides, sampled at the same points of the shared curve (the
    second mirrored when reversed), are one curve: an independent check of the sides and
    directions found. Both sides are exact NURBS evaluations of conforming edges (equal
    control points), so they agree to round-off: 1e-12 of the body's size."""
    size = max(np.ptp(s.control_points.reshape(-1, 3), axis=0).max() for s in surfaces)
    for face in topology.interfaces:
        a = side_curves(patch_from_surface(surfaces[face.a]))[face.edge_a]
        b = side_curves(patch_from_surface(surfaces[face.b]))[face.edge_b]
        assert np.abs(a - (b[::-1] if face.reversed else b)).max() <= 1e-12 * size, face


def test_a_box_is_six_faces_joined_along_twelve_edges(solids_3dm):
    with warnings.catch_warnings():
        warnings.simplefilter("error")          # nothing to warn about: no face is trimmed
        surfaces, topology, info = read_body(solids_3dm, ["box"])
    assert len(surfaces) == 6 and info["faces"] == [0, 1, 2, 3, 4, 5]
    assert info["units"] == "in" and info["names"] == ["box"] * 6 and info["skipped"] == {}
    assert topology.counts == {"shared": 12, "boundary": 0, "seam": 0, "non_manifold": 0,
                               "off_sides": 0}
    assert len(topology.interfaces) == 12 and all(i.conforming for i in topology.interfaces)
    # every face edge is in exactly one interface (a closed box has no free side)
    sides = sorted((i.a, i.edge_a) for i in topology.interfaces) + \
        sorted((i.b, i.edge_b) for i in topology.interfaces)
    assert sorted(sides) == sorted((k, e) for k in range(6) for e in ("u0", "u1", "v0", "v1"))
    assert_interfaces_meet(surfaces, topology)


def test_a_capped_cylinder_has_a_seam_and_trimmed_caps(solids_3dm):
    with pytest.warns(UserWarning) as caught:
        surfaces, topology, info = read_body(solids_3dm, ["walls"])
    messages = [str(w.message) for w in caught]
    # one line per trimmed cap, naming it
    assert messages == [f"{solids_3dm} face {k} (can) is trimmed; its whole underlying "
                        "surface is used" for k in (7, 8)]
    assert info["faces"] == [6, 7, 8] and info["trimmed"] == [7, 8]
    # the wall's seam, and the two circles where the caps' trimming loops meet the wall
    assert topology.counts == {"shared": 2, "boundary": 0, "seam": 1, "non_manifold": 0,
                               "off_sides": 2}
    (seam,) = topology.interfaces
    assert (seam.a, seam.b, {seam.edge_a, seam.edge_b}) == (0, 0, {"u0", "u1"})
    assert seam.conforming and not seam.reversed
    assert_interfaces_meet(surfaces, topology)


def test_a_sphere_has_a_seam_and_no_edge_at_its_poles(solids_3dm):
    with warnings.catch_warnings():
        warnings.simplefilter("error")          # the seam is joined: no open-seam warning
        surfaces, topology, _ = read_body(solids_3dm, ["ball"])
    assert len(surfaces) == 1
    assert topology.counts["seam"] == 1 and sum(topology.counts.values()) == 1
    assert_interfaces_meet(surfaces, topology)


def test_faces_are_chosen_by_number_name_or_layer(solids_3dm):
    with pytest.warns(UserWarning, match="trimmed"):
        _, everything, info = read_body(solids_3dm)
    assert info["faces"] == list(range(10))
    assert everything.counts == {"shared": 14, "boundary": 0, "seam": 2, "non_manifold": 0,
                                 "off_sides": 2}
    # two neighbours of the box: their one shared edge, and six free ones
    _, two, info = read_body(solids_3dm, [1, 0])
    assert info["faces"] == [1, 0]
    assert two.counts["shared"] == 1 and two.counts["boundary"] == 6
    (joint,) = two.interfaces
    assert {joint.a, joint.b} == {0, 1}
    with pytest.raises(InputError, match="no object or layer is named 'lid'; the names and "
                       "layers are 'Default', 'ball', 'box', 'can', 'walls'"):
        read_body(solids_3dm, ["lid"])
    with pytest.raises(InputError, match=r"face 10 out of range; the file holds 10 face\(s\)"):
        read_body(solids_3dm, [10])
    with pytest.raises(InputError, match="faces must be \"all\""):
        read_body(solids_3dm, "box")


def test_the_faces_command_reports_the_topology(solids_3dm):
    result = runner.invoke(cli.app, ["faces", str(solids_3dm)])
    assert result.exit_code == 0, result.output
    # the two cap circles are each shared by a cap and the can's wall: trim edges
    assert ("edges: 14 shared, 0 boundary, 2 seam(s), 0 non-manifold, 2 on trimming loops "
            "(2 shared by two faces, 0 free); 14 interface(s), 14 conforming") in result.output
    result = runner.invoke(cli.app, ["faces", "--json", str(solids_3dm)])
    topology = json.loads(result.output)["topology"]
    assert (topology["shared"], topology["seam"], len(topology["interfaces"])) == (14, 2, 14)
    assert topology["interfaces"][0].keys() == {"a", "edge_a", "b", "edge_b", "reversed",
                                                "conforming"}


# -- STEP, through OpenCASCADE ---------------------------------------------------------------
def write_solids_step(path, unit="MM"):
    """A 1 × 2 × 3 box and a cylinder of radius 1, height 2, as B-spline faces
    (``BRepBuilderAPI_NurbsConvert``) of one STEP file written in ``unit``."""
    from OCP.BRep import BRep_Builder
    from OCP.BRepBuilderAPI import BRepBuilderAPI_NurbsConvert
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox, BRepPrimAPI_MakeCylinder
    from OCP.gp import gp_Ax2, gp_Dir, gp_Pnt
    from OCP.Interface import Interface_Static
    from OCP.STEPControl import STEPControl_AsIs, STEPControl_Writer
    from OCP.TopoDS import TopoDS_Compound

    compound, builder = TopoDS_Compound(), BRep_Builder()
    builder.MakeCompound(compound)
    axis = gp_Ax2(gp_Pnt(5, 0, 0), gp_Dir(0, 0, 1))
    for shape in (BRepPrimAPI_MakeBox(1.0, 2.0, 3.0).Shape(),
                  BRepPrimAPI_MakeCylinder(axis, 1.0, 2.0).Shape()):
        builder.Add(compound, BRepBuilderAPI_NurbsConvert(shape, True).Shape())
    writer = STEPControl_Writer()
    Interface_Static.SetCVal_s("write.step.unit", unit)
    try:
        assert writer.Transfer(compound, STEPControl_AsIs) == 1
        assert writer.Write(str(path)) == 1
    finally:                     # a process-wide setting: later writers get millimetres
        Interface_Static.SetCVal_s("write.step.unit", "MM")
    return path


@pytest.fixture(scope="module")
def solids_step(tmp_path_factory):
    pytest.importorskip("OCP", reason="the 'cad-step' extra (cadquery-ocp) is not installed")
    return write_solids_step(tmp_path_factory.mktemp("body") / "solids.step")


def test_a_step_box_and_cylinder(solids_step):
    with pytest.warns(UserWarning) as caught:
        surfaces, topology, info = read_body(solids_step)
    # the cylinder's caps: planes bounded by circles
    assert [str(w.message) for w in caught] == [
        f"{solids_step} face {k} is trimmed; its whole underlying surface is used"
        for k in info["trimmed"]] and len(info["trimmed"]) == 2
    assert len(surfaces) == 9 and info["units"] == "mm"
    assert topology.counts == {"shared": 14, "boundary": 0, "seam": 1, "non_manifold": 0,
                               "off_sides": 2}
    assert len(topology.interfaces) == 13 and all(i.conforming for i in topology.interfaces)
    assert_interfaces_meet(surfaces, topology)


def test_a_step_body_in_metres_keeps_its_unit(tmp_path):
    pytest.importorskip("OCP", reason="the 'cad-step' extra (cadquery-ocp) is not installed")
    path = write_solids_step(tmp_path / "metres.step", "M")
    surfaces, topology, info = read_body(path, [0, 1, 2, 3, 4, 5])
    assert info["units"] == "m" and topology.counts["shared"] == 12
    # OpenCASCADE's box of 1 × 2 × 3 mm is written as 0.001 × 0.002 × 0.003 m and read in
    # the file's numbers (millimetres divided by 1000 twice over: round-off)
    extent = np.ptp(np.concatenate([s.control_points.reshape(-1, 3) for s in surfaces]), axis=0)
    assert extent == pytest.approx([1e-3, 2e-3, 3e-3], rel=1e-12)


# -- the scenario key surface.faces -----------------------------------------------------------
def cad_scenario(folder, source, surface: str):
    """A scenario reading ``source`` (copied beside it) with the ``[surface]`` lines given."""
    import shutil

    shutil.copy(source, folder / source.name)
    path = folder / "case.toml"
    path.write_text(f'[surface]\nshape = "cad"\npath = "{source.name}"\n{surface}\n'
                    '[material]\nw10 = 1.0\nw01 = 1.0\n[boundary]\nu0 = "pinned"\n'
                    '[[load]]\nkind = "pressure"\nq = -1.0\n[solve]\nkind = "static"\n')
    return path


def scenario_error(path) -> str:
    from splinedeform.errors import ScenarioError
    from splinedeform.scenario import build, load_scenario

    with pytest.raises(ScenarioError) as info:
        build(load_scenario(path))
    return str(info.value)


def test_one_face_chosen_by_number_is_read_as_face_is(solids_3dm, tmp_path):
    from splinedeform.scenario import build, load_scenario

    by_faces = build(load_scenario(cad_scenario(tmp_path, solids_3dm, 'faces = [3]')))
    by_face = build(load_scenario(cad_scenario(tmp_path, solids_3dm, 'face = 3')))
    # the same face read by the same reader twice: the same numbers
    # (to one rounding: the reader's arithmetic is the same both times)
    np.testing.assert_allclose(by_faces.surface.control_points,
                               by_face.surface.control_points, rtol=1e-15, atol=0)
    assert by_faces.units == by_face.units == "in"


def test_faces_are_checked_where_they_are_given(solids_3dm, tmp_path):
    message = scenario_error(cad_scenario(tmp_path, solids_3dm, 'faces = ["lid"]'))
    assert "surface.faces" in message and "no object or layer is named 'lid'" in message
    assert "'ball', 'box', 'can', 'walls'" in message
    message = scenario_error(cad_scenario(tmp_path, solids_3dm, 'faces = [12]'))
    assert "surface.faces" in message and "face 12 out of range" in message
    message = scenario_error(cad_scenario(tmp_path, solids_3dm, 'face = 1\nfaces = [2]'))
    assert "surface.faces: give face (one face) or faces (a body), not both" in message
    message = scenario_error(cad_scenario(tmp_path, solids_3dm, 'faces = "some"'))
    assert "surface.faces" in message and 'expected "all" or an array of integers' in message
    message = scenario_error(cad_scenario(tmp_path, solids_3dm, 'faces = [1, "box"]'))
    assert "surface.faces" in message


def test_a_body_of_several_faces_is_built_and_runs(solids_3dm, tmp_path):
    from splinedeform.body import BodyModel
    from splinedeform.body.body import Body
    from splinedeform.pipeline import run
    from splinedeform.scenario import build, load_scenario

    path = cad_scenario(tmp_path, solids_3dm, 'faces = ["box"]')
    # a closed box has no boundary edge; the preset of one edge alone is refused
    assert "boundary: a body takes one preset for every boundary edge" in scenario_error(path)
    path.write_text(path.read_text().replace('u0 = "pinned"', ''))
    built = build(load_scenario(path))
    assert isinstance(built.surface, Body) and isinstance(built.model, BodyModel)
    assert built.surface.faces == (0, 1, 2, 3, 4, 5) and built.units == "in"
    # the closed box under a pressure: a self-equilibrated load, solved with its mean
    # motion held; every face moves
    result = run(load_scenario(path), tmp_path / "out")
    assert all(np.abs(n[-1] - s.control_points).max() > 0
               for n, s in zip(result.nets, built.surface.patches))


def test_a_face_that_cannot_be_deformed_is_skipped_and_said_why(tmp_path):
    from splinedeform.cad import NurbsPatch, write_3dm

    knots = np.array([0, 0, 0, 1, 1, 1.0])
    unclamped = np.array([-0.2, -0.1, 0, 1, 1.1, 1.2])
    x, y = np.meshgrid([0, 0.5, 1], [0, 0.5, 1], indexing="ij")
    flat = np.stack([x, y, 0 * x], -1)
    # rank-3 weights on knots that are not clamped: general weights need clamped knots
    general = NurbsPatch((2, 2), unclamped, knots, flat, 1 + 0.5 * np.eye(3))
    path = write_3dm(tmp_path / "two.3dm", [general, NurbsPatch((2, 2), knots, knots, flat,
                                                                np.ones((3, 3)))])
    surfaces, topology, info = read_body(path)
    assert len(surfaces) == 1 and info["faces"] == [1] and list(info["skipped"]) == [0]
    assert "weights are not a product" in info["skipped"][0]
    assert "not clamped" in info["skipped"][0]
    # a plain surface: no edges in the file; the matching finds its 4 sides free
    assert topology.counts == {"shared": 0, "boundary": 4, "seam": 0, "non_manifold": 0,
                               "off_sides": 0, "joined_by_geometry": 0}
    with pytest.raises(InputError, match="none of the faces chosen can be deformed: face 0: "):
        read_body(path, [0])


def test_a_file_without_surfaces_is_the_path_s_fault(tmp_path):
    empty = tmp_path / "src" / "empty.3dm"
    empty.parent.mkdir()
    r3.File3dm().Write(str(empty), 7)
    message = scenario_error(cad_scenario(tmp_path, empty, 'faces = "all"'))
    assert "surface.path" in message and "empty.3dm: the file holds no surface" in message
