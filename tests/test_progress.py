"""Progress of a numerical solve: the simulated time the integrators reach, and its bar.

The integrators report the simulated time after each interval between stops (the one-step
methods, Newmark) or at each right-hand side evaluation (``solve_ivp``); the bar shows
``t = … of t_end`` and the time left, estimated from the simulated seconds per wall-clock
second.
"""

from __future__ import annotations

import io

import numpy as np
import pytest
from rich.console import Console
from typer.testing import CliRunner

import splinedeform as sd
from splinedeform import cli
from splinedeform._progress import StageProgress, reporting_simulated_time, simulated_time

from tiny_scenario import DYNAMIC

T_END = 2.0


@pytest.fixture(scope="module")
def model():
    surf = sd.shapes.plane(size=(1.0, 1.0), cells=(3, 3), degree=3, knots="open")
    mat = sd.Material(mass=1.0, damping=0.5, w10=1.0, w01=1.0, w20=0.0, w11=0.0, w02=0.0)
    return sd.Model(surf, mat, boundary="clamped")


@pytest.mark.parametrize("method, options", [("radau7", {}), ("genalpha", {"dt": 0.01}),
                                              ("newmark", {"dt": 0.01}),
                                              ("rk45", {"rtol": 1e-4, "atol": 1e-8})])
def test_integrators_report_the_simulated_time_up_to_the_end(model, method, options):
    reached: list[tuple[float, float]] = []
    load = sd.Uniform((0, 0, -1.0), profile=sd.Step(0.0, 1.0))
    with reporting_simulated_time(lambda t, t_end: reached.append((t, t_end))):
        model.dynamic(load, T_END, method=method, times=np.linspace(0, T_END, 5), **options)
    times = np.array([t for t, _ in reached])
    assert {t_end for _, t_end in reached} == {T_END}
    assert times.size >= 4                     # at least once per interval between frames
    assert np.all((times >= 0) & (times <= T_END))
    assert times[-1] == T_END                  # the last report is the end of the horizon
    if method != "rk45":                       # one-step methods and Newmark step forwards
        assert np.all(np.diff(times) > 0)


def test_reports_go_to_the_innermost_receiver_and_stop_with_its_block():
    outer: list[float] = []
    simulated_time(0.5, 2.0)                                   # nobody listens
    with reporting_simulated_time(lambda t, t_end: outer.append(t)):
        simulated_time(1.0, 2.0)
        with reporting_simulated_time(None):                   # silenced inside
            simulated_time(1.5, 2.0)
        simulated_time(2.0, 2.0)
    simulated_time(2.0, 2.0)
    assert outer == [1.0, 2.0]


def test_the_bar_shows_the_simulated_time_and_the_time_left():
    """2.5 simulated seconds per wall-clock second: at t = 5 of 10, 5 / 2.5 = 2 s are left."""
    text = io.StringIO()
    now = [0.0]
    console = Console(file=text, force_terminal=True, width=120, color_system=None)
    progress = StageProgress(console, clock=lambda: now[0])
    with progress:
        progress("solve", 0, 1)
        for clock, t in ((1.0, 2.5), (2.0, 5.0)):
            now[0] = clock
            progress.simulated("solve", t, 10.0)
        progress._progress.refresh()
        last = text.getvalue().split("\r")[-1]
    assert "t = 5 of 10" in last
    assert "0:00:02 left" in last


def test_quiet_progress_draws_nothing(model):
    text = io.StringIO()
    progress = StageProgress(Console(file=text, force_terminal=True), enabled=False)
    load = sd.Uniform((0, 0, -1.0), profile=sd.Step(0.0, 1.0))
    with progress, reporting_simulated_time(progress.receiver("solve")):
        progress("solve", 0, 1)
        model.dynamic(load, T_END, method="radau7")
    assert text.getvalue() == ""


def test_the_command_line_shows_the_simulated_time_of_a_numerical_solve(tmp_path):
    scenario = tmp_path / "tiny.toml"
    scenario.write_text(DYNAMIC + 'method = "radau7"\n\n[output]\nformats = []\n')
    runner = CliRunner()
    shown = runner.invoke(cli.app, ["run", str(scenario)])
    assert shown.exit_code == 0, shown.output
    assert "t = 2 of 2" in shown.stderr                     # t_end = 2 of the scenario
    quiet = runner.invoke(cli.app, ["run", str(scenario), "--quiet"])
    assert quiet.exit_code == 0 and quiet.stderr == "" and quiet.stdout == ""
