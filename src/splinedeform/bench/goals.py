"""The goals of the cost study (issues 10 and 25), read off the rows of one run.

Each goal is a ratio *integrator time / analytic time* on one line of the study: the
fastest integrator of the line (a run stopped at the budget counts with its extrapolated
cost when that is lower than every finished run) over the faster of the two analytic rows;
for the bench plate's net sizes (issue 25) over the README's default call alone (the row
``analytic``: ``Model.dynamic(load, t_end)``, the library as it ships), ≥ ×5 at 32² and
64², ≥ ×20 at 128².
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from .bookkeeping import Row, fastest, fastest_estimate


@dataclass
class Goal:
    """A goal line: what was asked, what was measured, whether it holds."""

    name: str
    target: str
    measured: str
    met: bool | None
    limit: str = ""


def _line(rows: Sequence[Row], regime: str, case: str | None = None,
          cells: int | None = None, family: str = "clamped") -> list[Row]:
    return [r for r in rows if r.regime == regime and r.family == family
            and (case is None or r.case == case) and (cells is None or r.cells == cells)]


def ratio(line: Sequence[Row], default_call: bool = False
          ) -> tuple[float, Row | None, Row | None, bool]:
    """``(integrator / analytic, analytic row, integrator row, extrapolated)`` of a line
    (``default_call``: the analytic row is the default call's, not the faster of the two)."""
    analytic = fastest([r for r in line if r.analytic
                        and (not default_call or r.solver == "analytic")])
    numerical = [r for r in line if not r.analytic]
    guess = fastest_estimate(numerical)
    best = fastest(numerical)
    if analytic is None:
        return math.nan, None, guess or best, guess is not None
    if guess is not None:
        return guess.estimate / analytic.seconds, analytic, guess, True
    if best is not None:
        return best.seconds / analytic.seconds, analytic, best, False
    stopped = [r for r in numerical if r.status == "over budget" and math.isfinite(r.seconds)]
    if stopped:                                     # every run stopped too early: a lower bound
        low = min(stopped, key=lambda r: r.seconds)
        return low.seconds / analytic.seconds, analytic, low, True
    return math.nan, analytic, None, False


def _describe(a: Row | None, n: Row | None, extrapolated: bool) -> str:
    if a is None or n is None:
        return "not measured"
    analytic = f"{a.solver} {a.seconds:.3g} s ({a.setting})"
    if extrapolated and math.isfinite(n.estimate):
        integrator = (f"{n.solver} ≈{n.estimate:.3g} s extrapolated from "
                      f"{n.progress:.0%} of t_end")
    elif extrapolated:
        integrator = f"{n.solver} > {n.seconds:.3g} s (stopped at the budget; a lower bound)"
    else:
        integrator = f"{n.solver} {n.seconds:.3g} s ({n.setting}, error {n.error:.0e})"
    return f"{analytic} vs {integrator}"


def _goal(name: str, target: float, line: Sequence[Row], default_call: bool = False) -> Goal:
    value, a, n, extrapolated = ratio(line, default_call)
    if not math.isfinite(value):
        return Goal(name, f"≥ ×{target:g}", "not measured", None)
    shown = ("≥ " if extrapolated and n is not None and not math.isfinite(n.estimate) else
             "≈" if extrapolated else "") + f"×{value:.3g}"
    return Goal(name, f"≥ ×{target:g}", f"{shown}: {_describe(a, n, extrapolated)}",
                value >= target)


def issue_goals(rows: Sequence[Row], frames: int, target: float) -> list[Goal]:
    """The goals of issues 10 and 25 that the rows measure (a goal whose line is absent
    says so)."""
    goals = []
    for cells, wanted in ((32, 5.0), (64, 5.0), (128, 20.0)):
        goals.append(_goal(f"bench plate {cells}², one load, {frames} frames, {target:g}, "
                           "default call", wanted, _line(rows, "size", cells=cells), True))
    light = [r for r in _line(rows, "horizon", "light damping, 100 periods")
             if r.cells == max((x.cells for x in rows if x.case == "light damping, 100 periods"),
                               default=0)]
    cells = light[0].cells if light else 32
    goals.append(_goal(f"light damping (γ = 0.05, β = 0), 100 periods, {cells}²", 300.0, light))
    load = _line(rows, "load case")
    cells = load[0].cells if load else 32
    goals.append(_goal(f"each additional load case on a solved model, {cells}²", 20.0, load))
    state = _line(rows, "one state")
    cells = state[0].cells if state else 64
    goals.append(_goal(f"one state at a single arbitrary time, {cells}²", 100.0, state))
    return goals
