"""Length units of CAD files: read, computed in, reported and written back, checked by
rhino3dm and OpenCASCADE reading the files themselves."""

import json

import numpy as np
import pytest

from splinedeform.cad import NurbsPatch
from splinedeform.errors import InputError
from splinedeform.pipeline import run
from splinedeform.scenario import load_scenario

S = np.sqrt(0.5)


def roof(units=None) -> NurbsPatch:
    """A quarter cylinder of radius 2, length 3, split once in v (3 x 3 poles)."""
    ring = 2.0 * np.array([[1.0, 0, 0], [1, 1, 0], [0, 1, 0]])
    points = np.stack([ring, ring + [0, 0, 1.5], ring + [0, 0, 3.0]], axis=1)
    return NurbsPatch((2, 2), np.array([0, 0, 0, 1, 1, 1.0]), np.array([0, 0, 0, 1, 1, 1.0]),
                      points, np.outer([1, S, 1], [1, 1, 1]), units)


def _case(folder, cad: str, fmt: str, extra: str = "") -> object:
    (folder / "case.toml").write_text(
        f'[surface]\nshape = "cad"\npath = "{cad}"\n{extra}\n[material]\nw10 = 1.0\n'
        'w01 = 1.0\n[boundary]\nv0 = "clamped"\n[[load]]\nkind = "pressure"\nq = 1.0\n'
        f'[solve]\nkind = "static"\nframes = 2\n[output]\nformats = ["{fmt}", "report"]\n')
    return load_scenario(folder / "case.toml")


def test_units_are_checked():
    with pytest.raises(InputError, match="NURBS patch units must be one of um, mm, cm, m"):
        roof("furlong")


def test_step_in_metres_round_trips_in_metres(tmp_path):
    pytest.importorskip("OCP", reason="the 'cad-step' extra (cadquery-ocp) is not installed")
    from OCP.STEPControl import STEPControl_Reader

    from splinedeform.cad_step import read_step, write_step
    from splinedeform.cad_step_read import read_faces

    write_step(tmp_path / "roof.step", [roof("m")])
    text = (tmp_path / "roof.step").read_text()
    assert "SI_UNIT($,.METRE.)" in text and "CARTESIAN_POINT('',(2.,0.,0.))" in text
    back = read_step(tmp_path / "roof.step")
    # the file's numbers, not scaled to millimetres (12 significant digits in STEP)
    assert back.units == "m" and np.abs(back.points - roof().points).max() <= 1e-11
    result = run(_case(tmp_path, "roof.step", "step"), tmp_path / "out")
    assert result.built.units == "m"
    from splinedeform.scenario import describe

    assert ("length unit", "m") in describe(result.scenario, result.built)
    report = json.loads((tmp_path / "out" / "report.json").read_text())
    assert report["surface"]["units"] == "m"
    # OpenCASCADE reads the output as metres: in its millimetres, 1000 x our initial net
    reader, faces, units = read_faces(tmp_path / "out" / "case.step")
    assert units == "m" and isinstance(reader, STEPControl_Reader)
    initial = read_step(tmp_path / "out" / "case.step", face=0)
    assert initial.units == "m" and np.abs(initial.points - roof().points).max() <= 1e-11


def test_iges_in_inches_is_read_and_written_in_inches(tmp_path):
    pytest.importorskip("OCP", reason="the 'cad-step' extra (cadquery-ocp) is not installed")
    from splinedeform.cad_step import read_step, write_step

    write_step(tmp_path / "roof.igs", [roof("in")])
    g = (tmp_path / "roof.igs").read_text().split("G0000003")[0]
    assert ",1,4HINCH," in g                     # unit flag 1 (inches), unit name INCH
    back = read_step(tmp_path / "roof.igs")
    # the file's numbers (10 significant digits in IGES), not 25.4 times them
    assert back.units == "in" and np.abs(back.points - roof().points).max() <= 1e-9


def test_3dm_in_inches_round_trips_in_inches_and_units_can_be_overridden(tmp_path):
    r3 = pytest.importorskip("rhino3dm", reason="the 'cad' extra (rhino3dm) is not installed")
    from splinedeform.cad import read_3dm, write_3dm

    write_3dm(tmp_path / "roof.3dm", [roof("in")])
    assert r3.File3dm.Read(str(tmp_path / "roof.3dm")).Settings.ModelUnitSystem == \
        r3.UnitSystem.Inches
    assert read_3dm(tmp_path / "roof.3dm").units == "in"
    run(_case(tmp_path, "roof.3dm", "3dm"), tmp_path / "out")
    written = r3.File3dm.Read(str(tmp_path / "out" / "case.3dm"))
    assert written.Settings.ModelUnitSystem == r3.UnitSystem.Inches
    report = json.loads((tmp_path / "out" / "report.json").read_text())
    assert report["surface"]["units"] == "in"
    # the initial surface is written with the numbers read: copied doubles
    assert np.abs(read_3dm(tmp_path / "out" / "case.3dm").points - roof().points).max() \
        <= 1e-15
    run(_case(tmp_path, "roof.3dm", "3dm", 'units = "mm"'), tmp_path / "mm")
    written = r3.File3dm.Read(str(tmp_path / "mm" / "case.3dm"))
    assert written.Settings.ModelUnitSystem == r3.UnitSystem.Millimeters
    assert np.abs(read_3dm(tmp_path / "mm" / "case.3dm").points - roof().points).max() <= 1e-15


def test_surface_without_units_is_written_without_units(tmp_path):
    r3 = pytest.importorskip("rhino3dm", reason="the 'cad' extra (rhino3dm) is not installed")
    from splinedeform.cad import read_3dm, write_3dm

    write_3dm(tmp_path / "plain.3dm", [roof()])
    assert str(r3.File3dm.Read(str(tmp_path / "plain.3dm")).Settings.ModelUnitSystem) == \
        "UnitSystem.None"
    assert read_3dm(tmp_path / "plain.3dm").units is None
