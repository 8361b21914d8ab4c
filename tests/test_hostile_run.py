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
