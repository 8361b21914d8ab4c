"""STEP and IGES round trips through OpenCASCADE (the 'cad-step' extra), evaluated by
OpenCASCADE's own evaluator (``Geom_BSplineSurface::Value`` of the surface it read)."""

import warnings

import numpy as np
import pytest

from splinedeform.cad import NurbsPatch, read_cad
from splinedeform.errors import InputError

pytest.importorskip("OCP", reason="the 'cad-step' extra (cadquery-ocp) is not installed")

from splinedeform.cad_step import read_step, write_step  # noqa: E402

S = np.sqrt(0.5)
#: OpenCASCADE writes reals with 12 significant digits in STEP and 10 in IGES: each stored
#: number is off by up to 5e-13 (5e-11 in IGES) of itself, and a point of the rational
#: surface, a weighted mean of such numbers, by a few of those units of the net's size
TOLERANCE = {".step": 3e-12, ".igs": 3e-9}


def quarter_cylinder() -> NurbsPatch:
    ring = np.array([[1.0, 0, 0], [1, 1, 0], [0, 1, 0]])
    points = np.stack([ring, ring + [0, 0, 2.0]], axis=1)
    return NurbsPatch((2, 1), np.array([0, 0, 0, 1, 1, 1.0]), np.array([0, 0, 1, 1.0]),
                      points, np.outer([1, S, 1], [1, 1]))


def wavy_patch() -> NurbsPatch:
    rng = np.random.default_rng(4)
    ku = np.array([0, 0, 0, 0, 0.2, 0.5, 0.5, 1, 1, 1, 1])
    kv = np.array([0, 0, 0, 0.7, 2, 2, 2])
    u, v = np.meshgrid(np.linspace(0, 1, 7), np.linspace(0, 2, 4), indexing="ij")
    points = np.stack([u, v, 0.3 * rng.standard_normal(u.shape)], axis=-1)
    return NurbsPatch((3, 2), ku, kv, points, rng.uniform(0.5, 2.0, u.shape))


def _occt_surface(path, face):
    """The B-spline surface OpenCASCADE reads from the file, untouched by our code."""
    from OCP.BRep import BRep_Tool
    from OCP.GeomConvert import GeomConvert

    from splinedeform.cad_step_read import read_faces

    return GeomConvert.SurfaceToBSplineSurface_s(BRep_Tool.Surface_s(read_faces(path)[1][face]))


@pytest.mark.parametrize("suffix", [".step", ".igs"])
@pytest.mark.parametrize("make", [quarter_cylinder, wavy_patch])
def test_round_trip_evaluated_by_opencascade(tmp_path, make, suffix):
    patch = make()
    path = write_step(tmp_path / f"s{suffix}", [quarter_cylinder(), patch])
    u = np.linspace(patch.knots_u[0], patch.knots_u[-1], 50)
    v = np.linspace(patch.knots_v[0], patch.knots_v[-1], 50)
    theirs = _occt_surface(path, 1)
    got = np.array([[[(q := theirs.Value(a, b)).X(), q.Y(), q.Z()] for b in v] for a in u])
    ours = patch.evaluate(u, v)
    scale = np.abs(patch.points).max()
    assert np.abs(got - ours).max() <= TOLERANCE[suffix] * scale
    back = read_step(path, face=1)
    assert back.degrees == patch.degrees
    assert np.abs(back.knots_u - patch.knots_u).max() <= TOLERANCE[suffix]
    assert np.abs(back.weights - patch.weights).max() <= TOLERANCE[suffix] * patch.weights.max()
    assert np.abs(back.evaluate(u, v) - ours).max() <= TOLERANCE[suffix] * scale


def test_read_cad_dispatches_on_the_suffix(tmp_path):
    write_step(tmp_path / "c.stp", [quarter_cylinder()])
    p = read_cad(tmp_path / "c.stp")
    x = p.evaluate(np.linspace(0, 1, 100), np.linspace(0, 1, 3))
    # the exact circle after 12-digit storage of its control points and weights
    assert np.abs(np.hypot(x[..., 0], x[..., 1]) - 1).max() <= TOLERANCE[".step"]


def test_bad_files_are_refused(tmp_path):
    (tmp_path / "notes.step").write_text("not a STEP file")
    with pytest.raises(InputError, match="notes.step: not a STEP file"):
        read_step(tmp_path / "notes.step")
    one = write_step(tmp_path / "one.igs", [quarter_cylinder()])
    with pytest.raises(InputError, match="one.igs: face 1 out of range"):
        read_step(one, face=1)
    with pytest.raises(InputError, match="missing.step: no such file"):
        read_step(tmp_path / "missing.step")


def test_box_faces_and_trimmed_faces_are_read_with_a_warning(tmp_path):
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox
    from OCP.STEPControl import STEPControl_AsIs, STEPControl_Writer

    from splinedeform.cad_step import bspline_surface

    writer = STEPControl_Writer()
    writer.Transfer(BRepPrimAPI_MakeBox(1.0, 2.0, 3.0).Shape(), STEPControl_AsIs)
    writer.Write(str(tmp_path / "box.step"))
    with pytest.warns(UserWarning, match=r"box.step face 0: its surface \(Geom_Plane\) is "
                                         "unbounded"):
        side = read_step(tmp_path / "box.step", face=0)
    corners = side.points.reshape(-1, 3)
    # the corners of the 1 × 2 × 3 box, written as exact decimals: round-off only
    off = np.abs(corners[..., None] - np.array([0.0, 1.0, 2.0, 3.0])).min(axis=-1)
    assert side.degrees == (1, 1) and off.max() <= 1e-12
    trimmed = BRepBuilderAPI_MakeFace(bspline_surface(wavy_patch()), 0.2, 0.8, 0.5, 1.5,
                                      1e-9).Face()
    writer = STEPControl_Writer()
    writer.Transfer(trimmed, STEPControl_AsIs)
    writer.Write(str(tmp_path / "trimmed.step"))
    with pytest.warns(UserWarning, match="trimmed.step face 0 is trimmed"):
        whole = read_step(tmp_path / "trimmed.step")
    assert whole.points.shape == wavy_patch().points.shape     # the whole surface


def test_a_scenario_reads_a_step_face(tmp_path):
    from splinedeform.scenario import build, load_scenario

    write_step(tmp_path / "roof.step", [wavy_patch(), quarter_cylinder()])
    (tmp_path / "case.toml").write_text(
        '[surface]\nshape = "cad"\npath = "roof.step"\nface = 1\n[material]\nw10 = 1.0\n'
        'w01 = 1.0\n[boundary]\nu0 = "pinned"\nu1 = "pinned"\n[solve]\nkind = "modes"\n')
    surface = build(load_scenario(tmp_path / "case.toml")).surface
    u, v = np.meshgrid(np.linspace(0, 1, 30), np.linspace(0, 1, 4), indexing="ij")
    x = surface.evaluate(u, v)
    assert np.abs(np.hypot(x[..., 0], x[..., 1]) - 1).max() <= TOLERANCE[".step"]


@pytest.mark.parametrize("fmt, suffix", [("step", ".step"), ("iges", ".igs")])
def test_scenario_exports_every_frame_as_step_or_iges(tmp_path, fmt, suffix):
    from splinedeform.pipeline import run
    from splinedeform.scenario import load_scenario

    from splinedeform.cad import refine

    write_step(tmp_path / "roof.step", [refine(quarter_cylinder(), 4)])
    (tmp_path / "case.toml").write_text(
        '[surface]\nshape = "cad"\npath = "roof.step"\n[material]\nw10 = 1.0\nw01 = 1.0\n'
        '[boundary]\nv0 = "clamped"\n[[load]]\nkind = "pressure"\nq = 1.0\n'
        f'[solve]\nkind = "static"\nframes = 3\n[output]\nformats = ["{fmt}"]\n')
    result = run(load_scenario(tmp_path / "case.toml"), tmp_path / "out")
    path = tmp_path / "out" / f"case{suffix}"
    assert (f"NURBS surfaces {suffix}", path) in result.outputs
    surface = result.built.surface
    u = np.linspace(0, surface.basis_u.length, 50)
    v = np.linspace(0, surface.basis_v.length, 50)
    nets = [surface.control_points, *result.nets]
    scale = np.abs(np.asarray(nets)).max()
    for face, net in enumerate(nets):
        theirs = _occt_surface(path, face)
        got = np.array([[[(q := theirs.Value(a, b)).X(), q.Y(), q.Z()] for b in v] for a in u])
        ours = surface.evaluate_grid(u, v, control_points=net)
        assert np.abs(got - ours).max() <= TOLERANCE[suffix] * scale
    assert np.abs(nets[-1] - nets[0]).max() > 1e-3                    # it did move
