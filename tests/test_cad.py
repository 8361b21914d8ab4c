"""Round trips through openNURBS (.3dm) evaluated by rhino3dm's own evaluator."""

import numpy as np
import pytest

from splinedeform.cad import NurbsPatch, read_3dm, write_3dm
from splinedeform.errors import InputError

r3 = pytest.importorskip("rhino3dm", reason="the 'cad' extra (rhino3dm) is not installed")

S = np.sqrt(0.5)


def quarter_cylinder() -> NurbsPatch:
    ring = np.array([[1.0, 0, 0], [1, 1, 0], [0, 1, 0]])
    points = np.stack([ring, ring + [0, 0, 2.0]], axis=1)
    weights = np.outer([1, S, 1], [1, 1])
    return NurbsPatch((2, 1), np.array([0, 0, 0, 1, 1, 1.0]), np.array([0, 0, 1, 1.0]),
                      points, weights)


def wavy_patch() -> NurbsPatch:
    rng = np.random.default_rng(4)
    ku = np.array([0, 0, 0, 0, 0.2, 0.5, 0.5, 1, 1, 1, 1])
    kv = np.array([0, 0, 0, 0.7, 2, 2, 2])
    u, v = np.meshgrid(np.linspace(0, 1, 7), np.linspace(0, 2, 4), indexing="ij")
    points = np.stack([u, v, 0.3 * rng.standard_normal(u.shape)], axis=-1)
    return NurbsPatch((3, 2), ku, kv, points, rng.uniform(0.5, 2.0, u.shape))


def test_quarter_cylinder_is_circular():
    # exact NURBS circle: radius error is round-off of a few operations; 1e-12 leaves margin
    p = quarter_cylinder().evaluate(np.linspace(0, 1, 100), np.linspace(0, 1, 100))
    assert np.abs(np.hypot(p[..., 0], p[..., 1]) - 1).max() <= 1e-12


@pytest.mark.parametrize("make", [quarter_cylinder, wavy_patch])
def test_3dm_round_trip_evaluated_by_rhino3dm(tmp_path, make):
    patch = make()
    path = write_3dm(tmp_path / "s.3dm", [patch])
    back = read_3dm(path)
    model = r3.File3dm.Read(str(path))
    srf = model.Objects[0].Geometry
    u = np.linspace(patch.knots_u[0], patch.knots_u[-1], 50)
    v = np.linspace(patch.knots_v[0], patch.knots_v[-1], 50)
    theirs = np.array([[[(q := srf.PointAt(a, b)).X, q.Y, q.Z] for b in v] for a in u])
    ours = patch.evaluate(u, v)
    # both evaluate the same rational polynomials of O(1) size: 1e-12 bounds the round-off
    assert np.abs(theirs - ours).max() <= 1e-12
    assert np.abs(back.evaluate(u, v) - ours).max() <= 1e-12
    assert back.degrees == patch.degrees


def test_bad_files_are_refused(tmp_path):
    text = tmp_path / "notes.3dm"
    text.write_text("not a CAD file")
    with pytest.raises(InputError, match="notes.3dm: not a .3dm"):
        read_3dm(text)
    empty = tmp_path / "empty.3dm"
    r3.File3dm().Write(str(empty), 7)
    with pytest.raises(InputError, match="empty.3dm: the file holds no surface"):
        read_3dm(empty)
    one = write_3dm(tmp_path / "one.3dm", [quarter_cylinder()])
    with pytest.raises(InputError, match="one.3dm: face 3 out of range"):
        read_3dm(one, face=3)
    with pytest.raises(InputError, match="degree"):
        NurbsPatch((0, 1), np.array([0, 1.0]), np.array([0, 0, 1, 1.0]),
                   np.zeros((1, 2, 3)), np.ones((1, 2)))


def test_only_really_trimmed_brep_faces_are_warned_about(tmp_path):
    import warnings

    from splinedeform.errors import InputWarning

    model = r3.File3dm()            # a capped cylinder: a whole side, two disc-trimmed caps
    model.Objects.AddBrep(r3.Brep.CreateFromCylinder(r3.Cylinder(r3.Circle(2.0), 3.0),
                                                     True, True))
    model.Write(str(tmp_path / "can.3dm"), 7)
    messages = []
    for face in range(3):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            patch = read_3dm(tmp_path / "can.3dm", face)
        assert all(issubclass(w.category, InputWarning) for w in caught)
        messages.append([str(w.message) for w in caught])
        assert patch.points.shape[-1] == 3
    assert messages == [[], *([f"{tmp_path / 'can.3dm'} face {k} is a trimmed Brep face; its "
                               "whole underlying surface is used"] for k in (1, 2))]


def test_non_positive_3dm_weight_is_refused(tmp_path):
    srf = r3.NurbsSurface.Create(3, True, 2, 2, 2, 2)       # bilinear, 2 x 2 poles
    for i, j in np.ndindex(2, 2):
        w = -1.0 if (i, j) == (1, 1) else 1.0
        srf.Points[i, j] = r3.Point4d(w * i, w * j, 0.0, w)   # homogeneous (w x, w y, w z, w)
    model = r3.File3dm()
    model.Objects.AddSurface(srf)
    model.Write(str(tmp_path / "odd.3dm"), 7)
    with pytest.raises(InputError, match=r"odd.3dm face 0: weight w\[1, 1\] = -1; NURBS "
                                         "weights must be > 0"):
        read_3dm(tmp_path / "odd.3dm")
