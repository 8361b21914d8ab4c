"""A run's STEP and IGES outputs keep the trims (outputs.py, outputs_body.py): a plane
trimmed by hand to a disc with a square window, and a body of two trimmed CAD faces, the
square with a circular hole and the disc filling it, each solved and its files read back
by OpenCASCADE's own readers (tests/occt_shapes.py)."""

import warnings

import numpy as np
import pytest

pytest.importorskip("OCP", reason="the 'cad-step' extra (cadquery-ocp) is not installed")

from occt_shapes import (area, free_edges, inside_points, model_area, read_shape,  # noqa: E402
                         sub_shapes, surface_points, valid)
from test_body_trimmed_cad import SCENARIO as SPLIT, split_step  # noqa: E402
from trim_scenario import TRIMMED  # noqa: E402

from splinedeform.pipeline import run  # noqa: E402
from splinedeform.scenario import load_scenario  # noqa: E402

#: the file's reals against ours, relative to the largest coordinate (1): STEP keeps 12
#: significant digits, IGES 9 (docs/cad.md)
POINT_TOL = {".step": 1e-11, ".igs": 1e-8}
#: OpenCASCADE's area of a face read back against ours over the same trimmed region: the
#: file's rounding (1e-12 in STEP, 1e-9 in IGES) and OpenCASCADE's adaptive integration
#: (asked for 1e-12); our rule is exact to round-off on these planes barely bent
AREA_TOL = 1e-8


def _run(folder, text, name):
    (folder / f"{name}.toml").write_text(text)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return run(load_scenario(folder / f"{name}.toml"), folder / "out")


def test_a_trimmed_plane_is_written_with_its_loops(tmp_path):
    text = TRIMMED + '[output]\nformats = ["step", "iges"]\n'
    result = _run(tmp_path, text.replace('[solve]\nkind = "static"\n',
                                         '[solve]\nkind = "static"\nframes = 2\n'), "disc")
    surface = result.built.surface
    assert surface.trim is not None and len(surface.trim.loops) == 2   # rim and window
    nets = [surface.control_points, *result.nets]
    uv = inside_points(surface)
    assert np.abs(nets[-1] - nets[0]).max() > 1e-4                    # it did move
    for suffix in (".step", ".igs"):
        path = tmp_path / "out" / f"disc{suffix}"
        assert (f"NURBS surfaces {suffix}", path) in result.outputs
        shape = read_shape(path)
        faces = sub_shapes(shape, "FACE")
        assert len(faces) == len(nets) and valid(shape)
        for face, net in zip(faces, nets):
            assert len(sub_shapes(face, "WIRE")) == 2
            assert area(face) == pytest.approx(model_area(surface, net), rel=AREA_TOL)
            want = surface.with_control_points(net).evaluate(uv[:, 0], uv[:, 1])
            assert np.abs(surface_points(face, uv) - want).max() < POINT_TOL[suffix]


@pytest.mark.parametrize("suffix", [".step", ".igs"])
def test_a_body_of_trimmed_faces_is_written_as_one_shell(tmp_path, suffix):
    split_step(tmp_path / "split.step")
    fmt = {".step": "step", ".igs": "iges"}[suffix]
    text = SPLIT.replace('formats = ["report", "obj"]', f'formats = ["{fmt}"]')
    result = _run(tmp_path, text, "split")
    body = result.built.surface
    assert [s.trim is not None for s in body.patches] == [True, True]
    path = tmp_path / "out" / f"split{suffix}"
    assert (f"NURBS surfaces {suffix}", path) in result.outputs
    shape, source = read_shape(path), read_shape(tmp_path / "split.step")
    faces = sub_shapes(shape, "FACE")
    assert len(faces) == 2 and valid(shape)
    # sewn along the circle as the source is: the square's four sides are the only free
    # edges, in both
    assert free_edges(source) == 4
    assert free_edges(shape) == free_edges(source)
    nets = [n[-1] for n in result.nets]
    assert max(np.abs(n - s.control_points).max() for n, s in zip(nets, body.patches)) > 1e-5
    # the ring (two wires) and the disc (one), each with its region's area, at the
    # deformed position
    for face in faces:
        wires = len(sub_shapes(face, "WIRE"))
        patch = [k for k, s in enumerate(body.patches) if len(s.trim.loops) == wires]
        assert len(patch) == 1
        surface, net = body.patches[patch[0]], nets[patch[0]]
        assert area(face) == pytest.approx(model_area(surface, net), rel=AREA_TOL)
        uv = inside_points(surface)
        want = surface.with_control_points(net).evaluate(uv[:, 0], uv[:, 1])
        assert np.abs(surface_points(face, uv) - want).max() < POINT_TOL[suffix]
