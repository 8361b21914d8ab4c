"""``surface.trim`` in scenario files: located errors and a trimmed plate run end to end."""

import json

import numpy as np
import pytest
from typer.testing import CliRunner

from splinedeform import cli
from splinedeform.errors import ScenarioError
from splinedeform.scenario import build, parse_scenario
from trim_scenario import HEAD, RIM, TAIL

def error_of(loops: str, tail: str = TAIL) -> str:
    with pytest.raises(ScenarioError) as info:
        build(parse_scenario(HEAD + loops + tail, source="trim.toml"))
    return str(info.value)


def test_a_loop_needs_one_curve():
    message = error_of('[[surface.trim.loops]]\nname = "rim"\nedge = "pinned"\n')
    assert "surface.trim.loops[1]" in message and "exactly one of polygon" in message


def test_a_bad_radius_is_located():
    message = error_of(RIM.replace("radius = 0.4", "radius = -0.4"))
    assert "surface.trim.loops[1].circle.radius" in message and "greater than 0" in message


def test_a_loop_outside_the_domain_is_located():
    message = error_of(RIM.replace("radius = 0.4", "radius = 0.55"))
    assert "surface.trim.loops[1]" in message and "'rim' reaches outside" in message


def test_crossing_loops_name_both():
    hole = ('[[surface.trim.loops]]\nname = "window"\n'
            'polygon = [[0.3, 0.3], [0.95, 0.3], [0.95, 0.6], [0.3, 0.6]]\n')
    message = error_of(RIM.replace("radius = 0.4", "radius = 0.3") + hole)
    assert "surface.trim.loops[2]" in message and "'window' crosses" in message
    assert "'rim'" in message


def test_a_self_intersecting_polygon_is_located():
    bow = ('[[surface.trim.loops]]\npolygon = [[0.2, 0.2], [0.8, 0.8], [0.8, 0.2], '
           '[0.2, 0.8]]\n')
    message = error_of(bow)
    assert "surface.trim.loops[1]" in message and "intersects itself" in message


def test_a_name_used_twice():
    hole = '[[surface.trim.loops]]\nname = "rim"\ncircle = { centre = [0.5, 0.5], radius = 0.1 }\n'
    assert "surface.trim.loops[2].name" in error_of(RIM + hole)


SHELL = TAIL.replace("w20 = 1.0\nw11 = 1.0\nw02 = 1.0",
                     'physics = "shell"\nE = 10000.0\nnu = 0.3\nthickness = 0.01\n'
                     'density = 1.0')
INTRINSIC = TAIL.replace("w02 = 1.0", 'w02 = 1.0\nphysics = "intrinsic"')


@pytest.mark.parametrize("tail, rigidity, bar", [
    (TAIL, 1.0, 1e-3),                                          # parametric, D = w20
    (SHELL, 1e4 * 0.01 ** 3 / (12 * (1 - 0.3 ** 2)), 2e-3),    # D = E t³/(12(1 − ν²))
    (INTRINSIC, 1.0, 1e-3),
])
def test_a_trimmed_plate_runs_end_to_end(tmp_path, tail, rigidity, bar):
    # the clamped disc of radius 0.4 under q = 1 (the rim's loop edge), as the parametric
    # and the intrinsic plate and as a thin shell: the largest displacement of the clipped
    # output mesh is the centre deflection q a⁴/(64 D) (10 × 10 cubic cells measured 1e-4,
    # 2.1e-4 and 6.9e-4 for the shell; the output grid of 41² points holds the centre);
    # 0.1 % is the task's bar, 0.2 % the shell's
    scenario = tmp_path / "disc.toml"
    scenario.write_text(HEAD + RIM + tail + '[output]\nformats = ["report", "vtu", "obj"]\n'
                        'resolution = 41\n')
    out = tmp_path / "out"
    result = CliRunner().invoke(cli.app, ["run", str(scenario), "-o", str(out), "-q"])
    assert result.exit_code == 0, result.output
    report = json.loads((out / "report.json").read_text())
    peak = report["solver"]["max displacement"]
    assert abs(peak / (0.4 ** 4 / (64 * rigidity)) - 1) < bar
    # the written mesh holds only the disc: every vertex within the radius (to the
    # round-off of the bisection, 1e-14)
    vertices = np.array([[float(x) for x in line.split()[1:]]
                         for line in (out / "disc.obj").read_text().splitlines()
                         if line.startswith("v ")])
    assert np.hypot(vertices[:, 0] - 0.5, vertices[:, 1] - 0.5).max() < 0.4 + 1e-14


def test_a_probe_outside_the_trimmed_region_is_located():
    message = error_of(RIM, TAIL + "[output]\nprobes = [[0.05, 0.05]]\n")
    assert "output.probes[1]" in message and "outside the trimmed region" in message


def test_the_default_probe_lies_in_the_trimmed_region(tmp_path):
    # a hole over the rectangle's centre: the probe moves to the nearest Gauss point of a
    # whole inside cell, outside the hole
    hole = "[[surface.trim.loops]]\ncircle = { centre = [0.5, 0.5], radius = 0.1 }\n"
    scenario = tmp_path / "ring.toml"
    scenario.write_text(HEAD + RIM + hole + TAIL + '[output]\nformats = ["report"]\n')
    out = tmp_path / "out"
    result = CliRunner().invoke(cli.app, ["run", str(scenario), "-o", str(out), "-q"])
    assert result.exit_code == 0, result.output
    name = next(k for k in json.loads((out / "report.json").read_text())["probes"]
                if k.startswith("p1"))
    u, v = (float(x) for x in name[name.index("(") + 1:name.index(")")].split(","))
    assert 0.1 < np.hypot(u - 0.5, v - 0.5) < 0.4


def test_holes_in_the_whole_rectangle_keep_its_edges():
    text = (HEAD.replace("[surface.trim]", "[surface.trim]\nrectangle = true")
            + '[[surface.trim.loops]]\nname = "bore"\n'
              'circle = { centre = [0.5, 0.5], radius = 0.2 }\n'
            + TAIL.replace("[[load]]", '[boundary]\nu0 = "clamped"\nv1 = "pinned"\n[[load]]'))
    built = build(parse_scenario(text, source="holed.toml"))
    assert built.model.constraints.edges == {"u0": "clamped", "u1": "free", "v0": "free",
                                             "v1": "pinned", "outer": "free", "hole1": "free"}
    # a point load inside the bore is refused at its key
    loaded = text.replace('kind = "uniform"\nforce = [0, 0, 1]',
                          'kind = "point"\nat = [0.5, 0.5]\nforce = [0, 0, 1]')
    with pytest.raises(ScenarioError) as info:
        build(parse_scenario(loaded, source="holed.toml"))
    assert "load[1].at" in str(info.value) and "outside the trimmed region" in str(info.value)
