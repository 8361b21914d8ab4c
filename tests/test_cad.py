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
