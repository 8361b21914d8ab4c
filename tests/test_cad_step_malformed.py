"""Malformed STEP and IGES files: a crash of OpenCASCADE, weights it would lose, a cone's
apex. Each file is written valid by OpenCASCADE, then its text is edited."""

import re

import numpy as np
import pytest

from splinedeform.cad import NurbsPatch
from splinedeform.errors import InputError

pytest.importorskip("OCP", reason="the 'cad-step' extra (cadquery-ocp) is not installed")

from splinedeform.cad_step import read_step, write_step  # noqa: E402

S = np.sqrt(0.5)


def quarter_cylinder() -> NurbsPatch:
    """Degrees (2, 1), 3 x 2 poles, weights (1, √½, 1) in u."""
    ring = np.array([[1.0, 0, 0], [1, 1, 0], [0, 1, 0]])
    points = np.stack([ring, ring + [0, 0, 2.0]], axis=1)
    return NurbsPatch((2, 1), np.array([0, 0, 0, 1, 1, 1.0]), np.array([0, 0, 1, 1.0]),
                      points, np.outer([1, S, 1], [1, 1]))


def _iges_edited(tmp_path, name, old, new):
    """The quarter cylinder as IGES with the first ``old`` of its B-spline entity's
    parameter lines replaced by ``new``, padding kept so every column stays in place."""
    text = write_step(tmp_path / "good.igs", [quarter_cylinder()]).read_text()
    lines = text.splitlines(keepends=True)
    k = next(i for i, line in enumerate(lines) if line[72] == "P" and old in line[:64])
    data = lines[k][:64].replace(old, new, 1)
    assert len(data.rstrip()) <= 64, "the edit must fit in the data columns"
    lines[k] = data.rstrip().ljust(64) + lines[k][64:]
    path = tmp_path / name
    path.write_text("".join(lines))
    return path


def test_iges_surface_with_negative_pole_count_is_an_error_not_a_crash(tmp_path):
    # 128, K1, K2, M1, M2: K1 = -2 is a negative count of poles (K1 + 1) in u;
    # OpenCASCADE dies of a segmentation fault reading it
    bad = _iges_edited(tmp_path, "negative.igs", "128,2,1,2,1,", "128,-2,1,2,1,")
    with pytest.raises(InputError, match=r"negative.igs: OpenCASCADE crashed reading this "
                                         r"file \(signal SIG\w+\); the file is probably "
                                         "malformed"):
        read_step(bad)
    # the next read starts a fresh reader: the valid file reads, its circle intact
    # (10 significant digits in IGES: 5e-11 per number, a few of them per point)
    good = read_step(tmp_path / "good.igs")
    x = good.evaluate(np.linspace(0, 1, 50), np.linspace(0, 1, 3))
    assert np.abs(np.hypot(x[..., 0], x[..., 1]) - 1).max() <= 3e-9


def test_step_surface_with_one_row_of_poles_for_three_is_a_clear_error(tmp_path):
    # degree 2 with knots (0, 0, 0, 1, 1, 1) needs 3 rows of poles; keep the first only
    # (the weights too): OpenCASCADE drops the entity, or, in releases that crash on it,
    # the child's death is reported; either way the file is named
    text = write_step(tmp_path / "good.step", [quarter_cylinder()]).read_text()
    poles = re.search(r"B_SPLINE_SURFACE\(2,1,\((\s*\(#\d+,#\d+\))(.*?)\)\)", text, re.S)
    weights = re.search(r"RATIONAL_B_SPLINE_SURFACE\(\((\s*\([^()]*\))(.*?)\)\)", text, re.S)
    assert poles and weights
    text = text.replace(poles.group(0), f"B_SPLINE_SURFACE(2,1,({poles.group(1)}))")
    text = text.replace(weights.group(0), f"RATIONAL_B_SPLINE_SURFACE(({weights.group(1)}))")
    (tmp_path / "row.step").write_text(text)
    with pytest.raises(InputError, match=r"row.step: (the file holds no surface that "
                                         r"OpenCASCADE can read|OpenCASCADE crashed)"):
        read_step(tmp_path / "row.step")


def test_iges_weight_minus_one_is_refused_naming_file_face_and_weight(tmp_path):
    # the weights follow the knots, i fastest: w00 = 1, w10 = √½, …; w10 becomes -1
    bad = _iges_edited(tmp_path, "negative_weight.igs", "0.707106781,", "-1.00000000,")
    with pytest.raises(InputError, match=r"negative_weight.igs face 0: its B-spline surface "
                                         r"\(IGES entity 128, directory entry 5\) has weight "
                                         r"w\[1, 0\] = -1; NURBS weights must be > 0"):
        read_step(bad)
    # the unedited rational surface keeps its weights: √½ is written 0.707106781, off
    # by less than half a unit of its 9th decimal
    back = read_step(tmp_path / "good.igs")
    assert np.abs(back.weights - np.outer([1, S, 1], [1, 1])).max() <= 5e-10


def test_cone_with_its_apex_reads_as_a_nurbs_cone(tmp_path):
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeCone
    from OCP.STEPControl import STEPControl_AsIs, STEPControl_Writer

    writer = STEPControl_Writer()              # radius 1 at z = 0, the apex at z = 2
    writer.Transfer(BRepPrimAPI_MakeCone(1.0, 0.0, 2.0).Shape(), STEPControl_AsIs)
    writer.Write(str(tmp_path / "cone.step"))
    with pytest.warns(UserWarning, match=r"cone.step face 0: its surface "
                                         r"\(Geom_ConicalSurface\) is unbounded"):
        cone = read_step(tmp_path / "cone.step", face=0)
    (nu, nv), ku, kv = cone.degrees, cone.knots_u, cone.knots_v
    # u opened from a periodic B-spline: the domain is [t_n, t_{N}], a turn of 2π
    assert ku[-nu - 1] - ku[nu] == pytest.approx(2 * np.pi, rel=1e-12)
    x = cone.evaluate(np.linspace(ku[nu], ku[-nu - 1], 60), np.linspace(kv[nv], kv[-nv - 1], 20))
    # the exact cone r = 1 - z / 2 after 12-digit storage of the file's numbers
    assert np.abs(np.hypot(x[..., 0], x[..., 1]) - (1 - x[..., 2] / 2)).max() <= 1e-11
    assert x[..., 2].min() >= -1e-12 and x[..., 2].max() <= 2 + 1e-11
    apex = cone.points[:, np.argmax(cone.points[..., 2].max(axis=0))]
    # the apex is a pole of the net: one row of points at (0, 0, 2), up to storage
    assert np.abs(apex - [0, 0, 2]).max() <= 1e-11
