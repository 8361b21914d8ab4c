"""``physics = "shell"`` in scenario files: keys, cross-field rules, and the three solves.

References: the simply supported plate's frequencies ``π²(m² + n²)√(D/ρt)`` (closed form)
and the library's direct static solve, an independent code path from the modal dynamics.
"""

from __future__ import annotations

from math import pi

import numpy as np
import pytest

from splinedeform.errors import ScenarioError
from splinedeform.pipeline import run, summary_rows
from splinedeform.scenario import parse_scenario, scenario_to_toml

PLATE = """
title = "pinned square shell plate"

[surface]
shape = "plane"
cells = 8

[material]
physics = "shell"
E = 1.0e4
nu = 0.3
thickness = 0.01
density = 2.0
{extra}
[boundary]
u0 = "pinned"
u1 = "pinned"
v0 = "pinned"
v1 = "pinned"

[[load]]
kind = "point"
at = [0.5, 0.5]
force = [0.0, 0.0, -1.0]

[solve]
{solve}
"""


def scenario(solve: str, extra: str = ""):
    return parse_scenario(PLATE.format(solve=solve, extra=extra), source="plate.toml")


def test_modes_of_the_pinned_plate_and_the_written_scenario_reads_back(tmp_path):
    s = scenario('kind = "modes"\nmodes = 3\nframes = 4')
    assert parse_scenario(scenario_to_toml(s), source="plate.toml") == s
    result = run(s, tmp_path, progress=None)
    D = 1.0e4 * 0.01 ** 3 / (12 * (1 - 0.3 ** 2))
    # discretisation error of cubic splines on 8 × 8 cells: measured 6e-4 for the (1, 2) pair
    np.testing.assert_allclose(result.omegas, pi ** 2 * np.array([2, 5, 5]) * np.sqrt(D / 0.02),
                               rtol=2e-3)
    # mode shapes reported as their normal component (a scalar field per mode)
    assert result.mode_shapes.shape == (3, 11, 11)
    # the summary counts the coupled unknowns, not control points: 9 × 9 inner points × 3
    assert dict(summary_rows(result))["free unknowns (x, y, z coupled)"] == "243"
    assert np.abs(result.nets[1] - result.rest_net).max() > 0


def test_damped_step_settles_on_the_static_solve(tmp_path):
    static = run(scenario('kind = "static"\nframes = 2'), tmp_path / "s")
    omega1 = pi ** 2 * 2 * float(np.sqrt(1.0e4 * 0.01 ** 3 / (12 * (1 - 0.3 ** 2)) / 0.02))
    # γ = 2 ω₁ ρ t makes mode 1 critically damped (c = γ/(ρt)); after 40/ω₁ it has settled
    # to (1 + 40) e^-40 ≈ 2e-16, so the tolerance is the modal round-off
    gamma = 2 * omega1 * 0.02
    t_end = 40 / omega1
    dynamic = run(scenario(f'kind = "dynamic"\nt_end = {t_end!r}\nframes = 3\nmodes = 0',
                           extra=f"damping = {gamma!r}"), tmp_path / "d")
    d_static = static.nets[-1] - static.rest_net
    np.testing.assert_allclose(dynamic.nets[-1] - dynamic.rest_net, d_static,
                               atol=1e-8 * np.abs(d_static).max())
    assert dynamic.energy["kinetic"][0] == 0.0 and dynamic.energy["total"][-1] < 0


@pytest.mark.parametrize("extra, solve, located", [
    ("w20 = 1.0", 'kind = "static"', 'plate.toml:14: material.w20: does not apply to physics '
                                     '"shell"'),
    ("mass_matrix = \"lumped\"", 'kind = "static"', "material.mass_matrix: does not apply"),
    ("", 'kind = "dynamic"\nt_end = 1.0\nmethod = "rk45"', "solve.method: the shell"),
])
def test_plate_keys_and_numerical_methods_are_refused_with_their_line(extra, solve, located):
    with pytest.raises(ScenarioError, match=located):
        scenario(solve, extra)


def test_shell_keys_and_edges_are_refused_on_the_plate_models():
    text = PLATE.format(solve='kind = "static"', extra="").replace(
        'physics = "shell"', 'physics = "intrinsic"\nw10 = 1.0\nw01 = 1.0').replace(
        'u0 = "pinned"', 'u0 = "symmetry"')
    with pytest.raises(ScenarioError) as info:
        parse_scenario(text, source="plate.toml")
    message = str(info.value)
    assert 'material.E: does not apply to physics \'intrinsic\', only to "shell"' in message
    assert "boundary.u0: 'symmetry' is an edge of the Kirchhoff–Love shell only" in message
    missing = PLATE.format(solve='kind = "static"', extra="").replace("E = 1.0e4\n", "")
    with pytest.raises(ScenarioError, match='material.E: missing \\(physics "shell" needs it\\)'):
        parse_scenario(missing, source="plate.toml")


@pytest.mark.parametrize("shape, edge, kind, located", [
    ("half_sphere", "v1", "pole", None),
    ("half_sphere", "v1", "diaphragm", "boundary: .*v1 of 'half_sphere' is a pole"),
    ("cylinder", "u0", "clamped", "boundary: .*a closed direction has no edges"),
])
def test_shell_poles_and_closed_directions_in_a_scenario(shape, edge, kind, located):
    from splinedeform.scenario.build import build
    text = PLATE.format(solve='kind = "static"', extra="").replace(
        'shape = "plane"\ncells = 8', f'shape = "{shape}"\ncells = [8, 4]')
    text = text.replace('u0 = "pinned"\nu1 = "pinned"\nv0 = "pinned"\nv1 = "pinned"',
                        f'v0 = "clamped"\n{edge} = "{kind}"' if edge != "v0" else
                        f'{edge} = "{kind}"')
    s = parse_scenario(text, source="shell.toml")
    if located is None:
        assert build(s).model.edges[edge] == "pole"
    else:
        with pytest.raises(ScenarioError, match=located):
            build(s)
