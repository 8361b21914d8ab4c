"""Hostile and extreme scenarios run end to end: a located error and nothing written."""
from __future__ import annotations

import pytest

from splinedeform import ScenarioError
from splinedeform.pipeline import run
from splinedeform.scenario import parse_scenario

BASE = """\
[surface]
shape = "plane"
cells = 3

[material]
mass = {mass}
damping = {damping}
w10 = 1.0
w01 = 1.0

[boundary]
u0 = "clamped"
u1 = "clamped"

[[load]]
kind = "uniform"
force = [0.0, 0.0, {force}]

[solve]
kind = "dynamic"
t_end = 2.0
frames = 5

[output]
formats = ["json"]
"""


@pytest.mark.parametrize("mass, damping, force, key", [
    (1.0, 0.0, -1e308, "load[1].force[3]"),
    (1e-250, 0.0, -1e300, "material.mass = 1e-250"),   # scales the solvers take (1e-300: refused sooner)
])
def test_overflow_is_refused_naming_the_input_and_nothing_is_written(tmp_path, mass, damping, force, key):
    text = BASE.format(mass=mass, damping=damping, force=force)
    scenario = parse_scenario(text, source="case.toml")
    out = tmp_path / "out"
    with pytest.raises(ScenarioError) as info:
        run(scenario, out)
    assert "not finite" in str(info.value) and key in str(info.value)
    assert not out.exists() or not any(out.iterdir())


@pytest.mark.parametrize("method", ["analytic", "newmark"])
@pytest.mark.parametrize("force", [-1e-300, -1e-320])
def test_tiny_loads_give_the_unit_load_response_scaled(method, force):
    # linearity: the response to s F is s times the response to F. A denormal load (1e-320
    # keeps 3 significant digits) used to come out 0.4 % off; solved at order one and scaled
    # back, the nets' displacements are s d₁ rounded once, as the reference s d₁ is: the
    # tolerance 1e-12 relative leaves room for that one rounding only
    import numpy as np

    text = BASE.format(mass=1.0, damping=0.5, force="{force}").replace(
        "frames = 5", f'frames = 5\nmethod = "{method}"').replace('formats = ["json"]',
                                                                 "formats = []")
    unit = run(parse_scenario(text.format(force=-1.0)))
    tiny = run(parse_scenario(text.format(force=force)))
    rest = unit.built.surface.control_points
    scale = force / -1.0
    expected = scale * (unit.nets - rest)
    assert np.abs(expected).max() > 0
    np.testing.assert_allclose(tiny.nets - rest, expected, rtol=1e-12, atol=0)
    # the largest displacement |d| of a tiny d: its squares underflow, the norm must not
    assert tiny.max_displacement == pytest.approx(scale * unit.max_displacement, rel=1e-3)


def test_thousands_of_probes_are_sampled_at_once_and_match_the_solution():
    # probes of one sparse evaluation matrix against the solution's own displacement d(t, u, v)
    # at the same points (an independent evaluation path); rtol 1e-12: both sum the same
    # (p + 1)² products of B-spline values in a different order
    import numpy as np

    at = [(0.05 + 0.9 * i / 1999, 0.3 + 0.4 * (i % 7) / 6) for i in range(2000)]
    listed = ", ".join(f"[{u!r}, {v!r}]" for u, v in at)
    text = BASE.format(mass=1.0, damping=0.5, force=-1.0).replace(
        'formats = ["json"]', f"formats = []\nprobes = [{listed}]")
    result = run(parse_scenario(text))
    u, v = np.array(at).T
    expected = result.solution.displacement(result.times, u, v)        # (F, P, 3)
    got = np.stack(list(result.probes.values()), axis=1)
    np.testing.assert_allclose(got, expected, rtol=1e-12, atol=1e-15 * np.abs(expected).max())
