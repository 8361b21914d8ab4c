"""Scenarios whose [surface] is a NURBS surface of a CAD file (shape = "cad")."""

import warnings

import numpy as np
import pytest

import splinedeform as sd
from splinedeform.cad import NurbsPatch, refine, surface_from_patch, write_3dm
from splinedeform.errors import InputWarning, ScenarioError
from splinedeform.scenario import build, load_scenario

r3 = pytest.importorskip("rhino3dm", reason="the 'cad' extra (rhino3dm) is not installed")

S = np.sqrt(0.5)


def quarter_cylinder() -> NurbsPatch:
    """Exact quarter of the unit cylinder, length 2, knots split once, u domain [4, 5]."""
    ring = np.array([[1.0, 0, 0], [1, 1, 0], [0, 1, 0]])
    points = np.stack([ring, ring + [0, 0, 1.0], ring + [0, 0, 2.0]], axis=1)
    knots = np.array([0, 0, 0, 1, 1, 1.0])
    fine = refine(NurbsPatch((2, 2), knots, knots, points, np.outer([1, S, 1], [1, 1, 1])), 2)
    return NurbsPatch(fine.degrees, fine.knots_u + 4.0, 2.0 * fine.knots_v, fine.points,
                      fine.weights)


def scenario(folder, surface: str) -> str:
    text = (f'[surface]\nshape = "cad"\n{surface}\n[material]\nw10 = 1.0\nw01 = 1.0\n'
            '[boundary]\nu0 = "pinned"\nu1 = "pinned"\n'
            '[[load]]\nkind = "pressure"\nq = -1.0\n[solve]\nkind = "static"\n')
    path = folder / "case.toml"
    path.write_text(text)
    return path


def test_cad_surface_is_read_with_its_knots_and_weights(tmp_path):
    patch = quarter_cylinder()
    u = np.linspace(patch.knots_u[0], patch.knots_u[-1], 30)
    v = np.linspace(0, 2, 20)
    # exact NURBS circle: round-off only
    assert np.abs(np.hypot(*patch.evaluate(u, v)[..., :2].transpose(2, 0, 1)) - 1).max() < 1e-12
    (tmp_path / "parts").mkdir()
    write_3dm(tmp_path / "parts" / "roof.3dm", [patch, patch])
    built = build(load_scenario(scenario(tmp_path, 'path = "parts/roof.3dm"\nface = 1')))
    surf = built.surface
    assert isinstance(surf.basis_u, sd.RationalBasis)
    # the file's domain [4, 5] is translated to [0, 1]; same rational surface by two
    # evaluators (ours, after a write and read back): round-off of O(1) numbers
    ours = surf.evaluate_grid(u - 4.0, v)
    assert np.abs(ours - patch.evaluate(u, v)).max() <= 1e-12
    d = built.model.static(built.load).displacement(0.5, 1.0)
    same = sd.Model(surface_from_patch(patch), sd.Material(w10=1, w01=1),
                    boundary={"u0": "pinned", "u1": "pinned"})
    # the same model built twice from the same data: identical up to round-off
    assert np.allclose(d, same.static(sd.Pressure(-1.0)).displacement(0.5, 1.0),
                       rtol=1e-12, atol=0)
    # q = -1 acts against x_u × x_v, which points away from the axis: the roof moves in,
    # equally in x and y at 45° (mirror symmetry; round-off of the solve, 1e-10 relative)
    assert d[0] < 0 and abs(d[0] - d[1]) <= 1e-10 * abs(d[0]) and abs(d[2]) <= 1e-10 * abs(d[0])


def _error(tmp_path, surface: str) -> str:
    with pytest.raises(ScenarioError) as info:
        build(load_scenario(scenario(tmp_path, surface)))
    return str(info.value)


def test_bad_cad_files_are_refused_naming_file_and_problem(tmp_path):
    (tmp_path / "notes.txt").write_text("hello")
    assert "notes.txt: not a CAD file" in _error(tmp_path, 'path = "notes.txt"')
    (tmp_path / "fake.3dm").write_text("not openNURBS")
    assert "fake.3dm: not a .3dm" in _error(tmp_path, 'path = "fake.3dm"')
    r3.File3dm().Write(str(tmp_path / "empty.3dm"), 7)
    assert "empty.3dm: the file holds no surface" in _error(tmp_path, 'path = "empty.3dm"')
    write_3dm(tmp_path / "one.3dm", [quarter_cylinder()])
    message = _error(tmp_path, 'path = "one.3dm"\nface = 2')
    assert "one.3dm: face 2 out of range" in message and "surface.path" in message
    assert "surface.cells: does not apply" in _error(tmp_path, 'path = "one.3dm"\ncells = 4')
    assert "missing.3dm" in _error(tmp_path, 'path = "missing.3dm"')


def test_cad_surface_with_general_weights_is_deformed(tmp_path):
    """A face whose weights are not a product is read per control point and solved; the
    same model built from the patch directly gives the same answer (round-off, 1e-12)."""
    patch = quarter_cylinder()
    w = patch.weights.copy()
    w[1, 2] *= 1.5
    odd = NurbsPatch(patch.degrees, patch.knots_u, patch.knots_v, patch.points, w)
    write_3dm(tmp_path / "odd.3dm", [odd])
    built = build(load_scenario(scenario(tmp_path, 'path = "odd.3dm"')))
    assert built.surface.net_weights is not None
    d = built.model.static(built.load).displacement(0.5, 1.0)
    same = sd.Model(surface_from_patch(odd), sd.Material(w10=1, w01=1),
                    boundary={"u0": "pinned", "u1": "pinned"})
    want = same.static(sd.Pressure(-1.0)).displacement(0.5, 1.0)
    assert np.abs(d - want).max() <= 1e-12 * np.abs(want).max()


def test_degree_zero_surface_is_refused():
    # openNURBS itself cannot hold an order-1 (degree 0) surface that rhino3dm would build,
    # so the reader's check is fed a stand-in with rhino3dm's attribute names
    from types import SimpleNamespace

    from splinedeform.cad_3dm_read import _patch_from_rhino
    from splinedeform.errors import InputError

    with pytest.raises(InputError, match=r"flat.3dm face 0: surface of degree \(0, 2\)"):
        _patch_from_rhino(SimpleNamespace(OrderU=1, OrderV=3), "flat.3dm face 0")


def test_brep_face_is_read_whole_and_only_its_open_seam_is_warned_about(tmp_path):
    model = r3.File3dm()
    sphere = r3.Brep.CreateFromSphere(r3.Sphere(r3.Point3d(0, 0, 0), 2.0))
    model.Objects.AddBrep(sphere)
    model.Write(str(tmp_path / "ball.3dm"), 7)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        surf = build(load_scenario(scenario(tmp_path, 'path = "ball.3dm"'))).surface
    # the sphere's face is not trimmed; its u seam (first = last column) is not joined, its
    # v ends are poles (one point each), not a seam
    assert [str(w.message) for w in caught] == [
        f"{tmp_path / 'ball.3dm'} face 0 is closed in u (its first and last control points "
        "in u coincide) but the seam is not joined: its two sides are separate unknowns and "
        "move apart under load"]
    assert all(issubclass(w.category, InputWarning) for w in caught)
    # a revolved surface: weights a_i b_j, one rational basis per direction
    assert isinstance(surf.basis_u, sd.RationalBasis) and isinstance(surf.basis_v, sd.RationalBasis)
    u, v = np.meshgrid(*surf.sample_parameters(20), indexing="ij")
    # the rhino sphere is an exact NURBS sphere: radius 2 up to round-off
    assert np.abs(np.linalg.norm(surf.evaluate(u, v), axis=-1) - 2).max() < 1e-12


def _rhino_grid(srf, u, v) -> np.ndarray:
    """rhino3dm's own evaluator (openNURBS ``ON_NurbsSurface::Evaluate``) on ``u × v``."""
    return np.array([[[(q := srf.PointAt(a, b)).X, q.Y, q.Z] for b in v] for a in u])


@pytest.mark.parametrize("surface", [
    'shape = "cad"\npath = "roof.3dm"',                            # rational, general knots
    'shape = "cylinder"\ncells = [8, 3]\ndegree = 3',               # periodic x open
    'shape = "plane"\ncells = [4, 5]\ndegree = 2\nknots = "uniform"',  # Höllig's layout
])
def test_3dm_export_of_every_frame_evaluates_equal_in_rhino3dm(tmp_path, surface):
    from splinedeform.pipeline import run

    write_3dm(tmp_path / "roof.3dm", [quarter_cylinder()])
    text = (f"[surface]\n{surface}\n[material]\nw10 = 1.0\nw01 = 1.0\nmass = 1.0\n"
            '[boundary]\nv0 = "clamped"\n'
            '[[load]]\nkind = "uniform"\nforce = [0.0, 0.0, -1.0]\n'
            '[solve]\nkind = "dynamic"\nt_end = 1.0\nframes = 3\nmodes = 0\n'
            '[output]\nformats = ["3dm"]\n')
    (tmp_path / "case.toml").write_text(text)
    result = run(load_scenario(tmp_path / "case.toml"), tmp_path / "out", None)
    path = tmp_path / "out" / "case.3dm"
    assert ("NURBS surfaces .3dm", path) in result.outputs
    model = r3.File3dm.Read(str(path))
    objects = list(model.Objects)
    assert [o.Attributes.Name for o in objects] == ["initial"] + [
        f"frame {k}: time = {t:.9g}" for k, t in enumerate(result.times)]
    surf = result.built.surface
    u = np.linspace(0, surf.basis_u.length, 50)
    v = np.linspace(0, surf.basis_v.length, 50)
    nets = [surf.control_points] + list(result.nets)
    for obj, net in zip(objects, nets):
        srf = obj.Geometry
        assert (srf.OrderU - 1, srf.OrderV - 1) == (surf.basis_u.degree, surf.basis_v.degree)
        ours = surf.evaluate_grid(u, v, control_points=net)
        # one rational spline evaluated by two codes on O(1) coordinates: round-off only
        assert np.abs(_rhino_grid(srf, u, v) - ours).max() <= 1e-12
    assert np.abs(result.nets[-1] - surf.control_points).max() > 1e-3   # it did move
    if "roof" in surface:   # degrees, knots (translated to start at 0) and weights kept
        from splinedeform.cad import read_3dm

        given, back = quarter_cylinder(), read_3dm(path, face=len(nets) - 1)
        assert back.degrees == given.degrees
        # stored doubles copied through openNURBS; the shift 4.0 is exact in binary
        assert np.abs(back.knots_u - (given.knots_u - 4.0)).max() <= 1e-15
        assert np.abs(back.knots_v - given.knots_v).max() <= 1e-15
        assert np.abs(back.weights - given.weights).max() <= 1e-15


def test_poles_of_a_cad_sphere_move_as_one_point(tmp_path):
    model = r3.File3dm()
    model.Objects.AddBrep(r3.Brep.CreateFromSphere(r3.Sphere(r3.Point3d(0, 0, 0), 1.0)))
    model.Write(str(tmp_path / "ball.3dm"), 7)
    with pytest.warns(InputWarning, match="NURBS patch is closed in u"):
        from splinedeform.cad import read_3dm
        surf = surface_from_patch(read_3dm(tmp_path / "ball.3dm"))
    m = sd.Model(surf, sd.Material(w10=1.0, w01=1.0), boundary={"v0": "pole", "v1": "pole"})
    # a free membrane: the rigid translation (one per coordinate, λ = 0 up to round-off,
    # so ω ~ 1e-8), then positive frequencies
    omega = m.frequencies(2)
    assert omega[0] <= 1e-6 * omega[1] and omega[1] > 0.1
    d = m.dynamic(sd.Point(1.0, 0.0, (0, 0, 1.0)), t_end=0.5).control_points(0.5)
    for row in (d[:, 0], d[:, -1]):          # every pole's control points stay together
        assert np.abs(row - row[0]).max() <= 1e-12 * np.abs(d).max()


@pytest.mark.parametrize("written, problem", [
    ("roof\\u0000.3dm", "surface.path: contains a NUL character (at position 4)"),
    ("r" * 6000 + ".3dm", "surface.path: is too long (6004 characters"),
    ("a/" * 3000 + "roof.3dm", "surface.path: is too long (6008 characters"),
])
def test_unusable_path_is_a_located_error(tmp_path, written, problem):
    with pytest.raises(ScenarioError) as info:
        load_scenario(scenario(tmp_path, f'path = "{written}"'))
    assert f"case.toml:3: {problem}" in str(info.value)


def test_closed_nurbs_cylinder_with_an_unjoined_seam_is_warned_about_once():
    import warnings

    # the full circle of 4 quarter arcs: 9 poles, the first and the last at (1, 0)
    square = np.array([[1.0, 0], [1, 1], [0, 1], [-1, 1], [-1, 0], [-1, -1], [0, -1], [1, -1],
                       [1, 0]])
    ring = np.c_[square, np.zeros(9)]
    points = np.stack([ring, ring + [0, 0, 2.0]], axis=1)
    knots_u = np.array([0, 0, 0, 1, 1, 2, 2, 3, 3, 4, 4, 4.0])
    full = NurbsPatch((2, 1), knots_u, np.array([0, 0, 1, 1.0]), points,
                      np.outer([1, S, 1, S, 1, S, 1, S, 1], [1, 1]))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        surface_from_patch(full, source="pipe.3dm face 0")
        surface_from_patch(quarter_cylinder(), source="roof.3dm face 0")   # open: no warning
    assert [str(w.message) for w in caught] == [
        "pipe.3dm face 0 is closed in u (its first and last control points in u coincide) "
        "but the seam is not joined: its two sides are separate unknowns and move apart "
        "under load"]


def test_command_line_prints_a_cad_warning_as_one_line(tmp_path):
    pytest.importorskip("typer", reason="the 'tool' extra (command line) is not installed")
    from typer.testing import CliRunner

    from splinedeform import cli

    model = r3.File3dm()
    model.Objects.AddBrep(r3.Brep.CreateFromSphere(r3.Sphere(r3.Point3d(0, 0, 0), 2.0)))
    model.Write(str(tmp_path / "ball.3dm"), 7)
    result = CliRunner().invoke(cli.app, ["validate", str(scenario(tmp_path,
                                                                   'path = "ball.3dm"'))])
    assert result.exit_code == 0, result.output
    lines = [line for line in result.stderr.splitlines() if line.strip()]
    # one line: no category, no source file and line of the code that warned
    assert len(lines) == 1 and lines[0].startswith("warning: ") and "closed in u" in lines[0]
    assert "InputWarning" not in result.stderr and ".py:" not in result.stderr
