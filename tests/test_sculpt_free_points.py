"""``boundary.free_points``: moving control points listed one by one (what sculpt paints)."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from splinedeform import ScenarioError
from splinedeform.scenario import build, load_scenario, parse_scenario, scenario_to_toml

from tiny_scenario import BASE

# the plane of BASE has a 6 x 6 net (3 cells + degree 3), clamped at u0 and u1
POINTS = "free_points = [[2, 2], [2, 3], [3, 2], [3, 3]]\n"


def line_of(text: str, start: str) -> int:
    return next(i for i, line in enumerate(text.splitlines(), 1) if line.startswith(start))


def with_points(points: str) -> str:
    return BASE.replace('u1 = "clamped"\n', 'u1 = "clamped"\n' + points)


def test_listed_points_move_and_the_others_stay_at_rest():
    built = build(parse_scenario(with_points(POINTS), source="case.toml"))
    moving = ~built.fixed
    assert moving.sum() == 4 and moving[2:4, 2:4].all()
    assert built.model.n_free == 4              # the clamped edges do not touch rows 2, 3
    d = built.model.static(built.load).control_points() - built.surface.control_points
    assert np.all(d[built.fixed] == 0.0)        # fixed points are no unknowns: exactly at rest
    assert np.all(np.abs(d[~built.fixed][:, 2]) > 0)

def test_the_same_points_as_a_box_give_the_same_mask():
    # an independent path to the same set: the box around the Greville abscissae 1/3, 2/3
    # of rows 2, 3 (open cubic knots 0 0 0 0 1/3 2/3 1 1 1 1: 0, 1/9, 1/3, 2/3, 8/9, 1)
    box_text = BASE.replace('u1 = "clamped"\n', 'u1 = "clamped"\n'
                            "free_region = { u = [0.3, 0.7], v = [0.3, 0.7] }\n")
    box = build(parse_scenario(box_text, source="box.toml")).fixed
    listed = build(parse_scenario(with_points(POINTS), source="case.toml")).fixed
    assert box.shape == listed.shape and (~box).sum() == 4
    # boolean masks, no floating point: the same moving control points, as index sets
    assert set(zip(*np.nonzero(~box))) == set(zip(*np.nonzero(~listed)))


def test_free_points_survive_a_write_and_read():
    scenario = parse_scenario(with_points(POINTS), source="case.toml")
    again = parse_scenario(scenario_to_toml(scenario), source="again.toml")
    assert again.boundary.free_points == ((2, 2), (2, 3), (3, 2), (3, 3))


def test_an_index_off_the_net_names_file_line_and_key(tmp_path: Path):
    text = with_points("free_points = [\n  [2, 2],\n  [2, 9],\n]\n")
    path = tmp_path / "painted.toml"
    path.write_text(text)
    with pytest.raises(ScenarioError) as info:
        build(load_scenario(path))
    message = str(info.value)
    assert message.startswith(f"{path}:{line_of(text, '  [2, 9]')}: boundary.free_points[2]: ")
    assert "[2, 9] is not a control point" in message and "j in 0 .. 5" in message


@pytest.mark.parametrize("points, key, words", [
    ("free_points = [[2, -1]]\n", "boundary.free_points[1]", "an array of 2 integers"),
    ("free_points = [[2.5, 1]]\n", "boundary.free_points[1]", "an array of 2 integers"),
    ("free_points = []\n", "boundary.free_points", "is empty"),
    ("free_points = [[1, 1]]\nfree_region = { u = [0, 1] }\n", "boundary.free_points",
     "not both"),
])
def test_malformed_free_points_are_refused_at_their_line(points, key, words):
    text = with_points(points)
    with pytest.raises(ScenarioError) as info:
        parse_scenario(text, source="case.toml")
    message = str(info.value)
    assert f"case.toml:{line_of(text, 'free_points')}: {key}: " in message
    assert words in message
