"""Save writes one piecewise load per grab (per axis when the force turns), not one step
table per frame, and the loads sum to the page's force at every time."""

from __future__ import annotations

import numpy as np
import pytest

from splinedeform import loads as L
from splinedeform.scenario import parse_scenario
from splinedeform.sculpt.grabs import grab_chains
from splinedeform.sculpt.messages import PushMessage, SaveMessage
from splinedeform.sculpt.session import Session

SHEET = """
[surface]
shape = "plane"
cells = 3
[material]
w10 = 1.0
w01 = 1.0
damping = 1.0
[boundary]
u0 = "clamped"
[solve]
kind = "modes"
"""
R = 5


@pytest.fixture(scope="module")
def session():
    return Session(parse_scenario(SHEET, source="sheet.toml"), resolution=R, modes=None)


def _drag(index: int, t0: float, frames: int, direction=None, held: bool = False):
    """A drag as the page records it: a new force every 1/60 s, each push ending when the
    next starts; a turning spring force, or one along ``direction``."""
    times = t0 + np.arange(frames + 1) / 60.0
    pushes = []
    for k in range(frames):
        a = k / frames
        force = (np.asarray(direction) * (0.5 + a) if direction is not None
                 else np.array([np.sin(3 * a), 0.2 * a, -1.0 - a]))
        t_off = None if held and k == frames - 1 else float(times[k + 1])
        pushes.append(PushMessage(index=index, force=tuple(force), t_on=float(times[k]),
                                  t_off=t_off))
    return pushes


def _force(scenario, t: float) -> np.ndarray:
    """Σ force · s(t) of the scenario's point loads at ``t`` (the library's own profile)."""
    total = np.zeros(3)
    for load in scenario.loads:
        s = float(L.Piecewise(load.points)(np.array([t]))[0])
        total += s * np.asarray(load.force)
    return total


def _page_force(pushes, t: float) -> np.ndarray:
    on = [p for p in pushes if p.t_on <= t and (p.t_off is None or t < p.t_off)]
    return sum((np.asarray(p.force) for p in on), np.zeros(3))


def test_a_78_frame_drag_is_at_most_three_loads_and_the_same_force(session):
    """1.3 s of dragging at 60 frames per second: 78 pushes."""
    drag = _drag(3 * R + 2, 0.1, 78)
    scenario = session.to_scenario(SaveMessage(version=1, t_end=2.0, pushes=drag))
    # the spring turns the force in x, y and z: one piecewise table per axis, not 78 steps
    assert len(scenario.loads) == 3
    assert all(load.profile == "piecewise" and len(load.points) == 79 for load in scenario.loads)
    for t in np.linspace(0.0, 2.0, 241):
        # one axis per table, the page's components copied: equal to rounding of the sum
        assert np.allclose(_force(scenario, t), _page_force(drag, t), rtol=0, atol=1e-14)


def test_a_push_along_the_normal_is_one_load_and_two_grabs_two(session):
    first = _drag(3 * R + 2, 0.0, 40, direction=(0.0, 0.6, -0.8))
    second = _drag(R + 1, 1.0, 30, direction=(0.0, 0.0, 1.0), held=True)
    message = SaveMessage(version=1, t_end=2.0, pushes=first + second)
    assert [len(c) for c in grab_chains(message.pushes)] == [40, 30]
    scenario = session.to_scenario(message)
    assert len(scenario.loads) == 2 and all(ld.profile == "piecewise" for ld in scenario.loads)
    assert scenario.loads[1].points[-1][0] < 2.0                    # still held: no release
    for t in np.linspace(0.0, 2.0, 241):
        # s = F_k·F*/|F*|² times F*: exact up to a few roundings of numbers of size 1
        assert np.allclose(_force(scenario, t), _page_force(message.pushes, t),
                           rtol=0, atol=1e-14)
    assert len(scenario.output.probes) == 2
