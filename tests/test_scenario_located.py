"""Scenario files that used to fail deep inside the library: each one a located ScenarioError."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from splinedeform import ScenarioError
from splinedeform.pipeline import run
from splinedeform.scenario import build, load_scenario, parse_scenario

from tiny_scenario import BASE


def line_of(text: str, start: str) -> int:
    """Line (from 1) of the first line of ``text`` starting with ``start``."""
    return next(i for i, line in enumerate(text.splitlines(), 1) if line.startswith(start))


def run_error(text: str, tmp_path: Path | None = None) -> str:
    """The message of the ScenarioError raised on reading, building or running ``text``."""
    with pytest.raises(ScenarioError) as info:
        run(parse_scenario(text, source="case.toml"), None if tmp_path is None else tmp_path / "out")
    return str(info.value)


def test_periodic_knots_on_a_plane_are_refused_at_the_knots_key():
    text = BASE.replace("cells = 3\n", "cells = 5\nknots = [\"periodic\", \"open\"]\n")
    message = run_error(text)
    assert message.startswith(f"case.toml:{line_of(text, 'knots')}: surface.knots: ")
    assert "not closed in u" in message and "1 apart" in message


# -- values the solvers cannot carry ---------------------------------------------------------
@pytest.mark.parametrize("old, new, key", [
    ("w10 = 1.0", "w10 = 1e308", "material.w10"),
    ("[material]\n", "[material]\nmass = 1e-320\n", "material.mass"),
])
def test_weights_and_masses_beyond_double_range_name_their_key(old, new, key):
    # used to end in numpy's LinAlgError from the eigensolver
    text = BASE.replace(old, new)
    message = run_error(text)
    assert message.startswith(f"case.toml:{line_of(text, key.split('.')[1])}: {key}: ")
    assert "Rescale the units" in message


def test_a_net_with_every_point_clamped_says_nothing_can_move():
    text = BASE.replace("cells = 3", "cells = 1").replace(
        'u1 = "clamped"', 'u1 = "clamped"\nv0 = "clamped"\nv1 = "clamped"')
    message = run_error(text)
    assert message.startswith(f"case.toml:{line_of(text, '[boundary]')}: boundary: no free coordinate")
    assert "4 x 4 control points" in message and "modes" not in message


def test_an_absurd_angular_frequency_names_omega():
    # used to end in OverflowError from ω² in the harmonic response
    text = BASE.replace('profile = "step"', 'profile = "harmonic"\nomega = 1e300')
    message = run_error(text)
    assert message.startswith(f"case.toml:{line_of(text, 'omega')}: load[1].omega: ")
    assert "<= 1e+12" in message


def test_t_end_beyond_any_meaningful_phase_names_t_end():
    text = BASE.replace("t_end = 2.0", "t_end = 1e308")
    assert run_error(text).startswith(f"case.toml:{line_of(text, 't_end')}: solve.t_end: ")


# -- files ------------------------------------------------------------------------------------
def file_scenario(folder: Path, name: str) -> Path:
    scenario = folder / "case.toml"
    scenario.write_text(f'[surface]\nshape = "file"\npath = "{name}"\n'
                        '[material]\nw10 = 1.0\nw01 = 1.0\n[boundary]\nu0 = "clamped"\n'
                        '[solve]\nkind = "modes"\nmodes = 2\n[output]\nformats = []\n')
    return scenario


def file_error(scenario: Path) -> str:
    with pytest.raises(ScenarioError) as info:
        build(load_scenario(scenario))
    return str(info.value)


def test_a_net_file_claiming_two_billion_cells_is_refused_before_allocating(tmp_path):
    import json

    from splinedeform import shapes
    from splinedeform.export import write_control_nets

    surf = shapes.plane(cells=2, degree=2)
    write_control_nets(tmp_path, "net", surf, [0.0], surf.control_points[None])
    doc = json.loads((tmp_path / "net.json").read_text())
    doc["basis"]["u"]["cells"] = 2_000_000_000
    (tmp_path / "net.json").write_text(json.dumps(doc))
    message = file_error(file_scenario(tmp_path, "net.json"))
    assert "surface.path: " in message and "on 2000000000 cells has 2000000002 functions" in message
    assert "control_points has shape 4 in this direction" in message


@pytest.mark.parametrize("array", [
    np.full((4, 4, 3), "1.5"),                        # strings that numpy would parse
    np.full((4, 4, 3), True),
    np.zeros((4, 4, 3)) + 1j,
])
def test_a_point_grid_of_non_real_values_is_refused(tmp_path, array):
    np.save(tmp_path / "grid.npy", array)
    message = file_error(file_scenario(tmp_path, "grid.npy"))
    assert f"{tmp_path / 'case.toml'}:3: surface.path: " in message and "real numbers" in message


def test_a_pickled_point_grid_is_not_unpickled(tmp_path):
    marker = tmp_path / "unpickled"
    array = np.empty((2, 2, 3), dtype=object)
    array[...] = 0.0
    array[0, 0, 0] = Boom(marker)
    np.save(tmp_path / "grid.npy", array, allow_pickle=True)
    message = file_error(file_scenario(tmp_path, "grid.npy"))
    assert f"{tmp_path / 'case.toml'}:3: surface.path: cannot read grid.npy" in message
    assert not marker.exists()


class Boom:
    """Creates ``marker`` when unpickled."""

    def __init__(self, marker: Path) -> None:
        self.marker = marker

    def __reduce__(self):
        return (Path.touch, (self.marker,))
