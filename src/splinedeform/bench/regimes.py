"""Regimes b–e of the cost study, each line analytic against Radau IIA-7 at its cheapest
setting reaching the target (the strongest integrator: exact stage solves, LUs reused,
only the moving coordinate).

b. ``horizon``: ``P`` periods of the lowest mode (1 … 1000), light (``γ = 0.05, β = 0``)
   and heavy (``γ = 8``) damping, 200 frames, 16² (and the goal line: light, 100
   periods, 32², with five budgets, its search starting two levels of √2 finer than the
   16² setting: the finer net's modes need more steps);
c. ``load case``: one more load case on a model already solved, against a full integrator
   run of that case (the model is assembled for both);
d. ``one state``: the state at one arbitrary time ``t = 0.37 t_end`` from scratch
   (assembly, eigen-solution), against integrating to ``t``; the analytic call asks for
   that time, ``dynamic(load, t_end, times=[t])`` (modes chosen for it);
e. ``probes``: the displacement of five surface points at 200 frames against the whole
   control nets at the same frames.

Every line has the automatic mode count (``analytic``), all modes (``analytic-all``) and
Radau IIA-7; the reference is the all-modes solution.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np

from .. import loads
from . import analytic
from .bookkeeping import Row, numerical_row
from .cases import HEAVY, LIGHT, PLATE, Case, lowest_period, make_case, reference_t_end
from .search import search, setting_label, substeps
from .timing import assembly_seconds, median_run

DAMPINGS = {"light": LIGHT, "heavy": HEAVY, "plate": PLATE}
PROBES = ((0.4, 0.3), (0.5, 0.5), (0.25, 0.75), (0.8, 0.2), (0.6, 0.9))
STATE_AT = 0.37
"""The single time of regime d, as a fraction of ``t_end``."""


class _Limits:
    def __init__(self, target: float, budget: float):
        self.target, self.budget = target, budget


def _tag(rows: list[Row], regime: str, label: str) -> list[Row]:
    for r in rows:
        r.regime, r.case = regime, label
    return rows


def _line(case: Case, target: float, budget: float, start: int, times_given: bool = False
          ) -> tuple[list[Row], int | None]:
    """All modes (the reference), the automatic mode count and Radau IIA-7 on one case
    (``times_given``: the automatic modes chosen for the case's times, given at the call)."""
    full = analytic.all_modes(case)
    auto = analytic.automatic(case, target, times_given=times_given)
    assembly = assembly_seconds(case)
    tried, best = search(case, "radau7", start, _Limits(target, budget))
    label = setting_label("radau7", best) if best is not None else ""
    return [auto, full, numerical_row(case, "radau7", tried, best, assembly, label)], best


def horizon(cells: int, periods: float, damping: str, frames: int, target: float,
            budget: float, start: int) -> tuple[list[Row], int | None]:
    """Regime b: ``periods`` periods of the lowest mode of the net, 200 frames."""
    material = DAMPINGS[damping]
    t_end = periods * lowest_period("clamped", cells, material)
    case = make_case("clamped", cells, frames, t_end, material)
    rows, best = _line(case, target, budget, start)
    plural = "" if periods == 1 else "s"
    return _tag(rows, "horizon", f"{damping} damping, {periods:g} period{plural}"), best


def load_case(cells: int, frames: int, target: float, budget: float) -> list[Row]:
    """Regime c: a second load case on a solved model (median of five) against Radau IIA-7."""
    t_end = reference_t_end("clamped")
    times = np.linspace(0.0, t_end, frames)
    second = loads.Point(0.7, 0.6, (0.0, 0.0, -2.0), profile=loads.Step(0.2 * t_end))
    case = make_case("clamped", cells, frames, t_end, load=second)
    rows = []
    for solver, options in (("analytic-all", {}),
                            ("analytic", {"times": times, "tolerance": target})):
        model = case.fresh_model()
        first = make_case("clamped", cells, 2, t_end).load
        model.dynamic(first, t_end, **options).control_points(times)       # solved once
        seconds, (solution, nets) = median_run(lambda: _run(model, second, t_end, times,
                                                            options), repeats=5)
        if solver == "analytic-all":
            case.set_reference(nets, "all modes")
        report = dict(getattr(solution, "truncation", None) or {})
        row = Row("clamped", cells, model.n_free, solver, "exact" if not options else "ok",
                  seconds, error=_error(nets, case) if options else math.nan, runs=5,
                  modes=int(report.get("modes", model.n_free) or model.n_free),
                  bound=float(report.get("bound", math.nan)))
        row.setting = ("all modes, model solved" if not options else
                       analytic.automatic_label(target, row.modes, row.bound, model.n_free)
                       + ", model solved")
        rows.append(row)
    tried, best = search(case, "radau7", 0, _Limits(target, budget))
    label = setting_label("radau7", best) if best is not None else ""
    rows.append(numerical_row(case, "radau7", tried, best, 0.0, label))
    rows[-1].note = "full run of the second load case (model assembled)"
    return _tag(rows, "load case", "each additional load case")


def _run(model: Any, load: loads.Load, t_end: float, times: np.ndarray,
         options: dict[str, Any]) -> tuple[Any, np.ndarray]:
    solution = model.dynamic(load, t_end, **options)
    return solution, solution.control_points(times)


def _error(nets: np.ndarray, case: Case) -> float:
    return float(np.abs(nets - case.reference).max()) / case.scale


def one_state(cells: int, target: float, budget: float) -> list[Row]:
    """Regime d: the state at ``t = 0.37 t_end`` from scratch against integrating to ``t``."""
    t_end = reference_t_end("clamped")
    case = make_case("clamped", cells, 2, t_end)
    case.times = np.array([STATE_AT * t_end])
    rows, _ = _line(case, target, budget, 6, times_given=True)
    return _tag(rows, "one state", f"one state at t = {STATE_AT:g} t_end")


def probes(cells: int, frames: int, target: float, budget: float) -> list[Row]:
    """Regime e: five surface points against whole nets at ``frames`` frames."""
    case = make_case("clamped", cells, frames)
    nets_rows, best = _line(case, target, budget, 2)
    _tag(nets_rows, "probes", "whole control nets")
    u, v = (np.array(x) for x in zip(*PROBES))
    E = case.model.surface.evaluation_matrix(u, v).toarray()
    moved = case.reference - case.model.surface.control_points
    reference = np.einsum("pk,fkc->fpc", E, moved.reshape(case.times.size, -1, 3))
    scale = float(np.abs(reference).max())
    auto = next(r for r in nets_rows if r.solver == "analytic")
    finer = 0 < auto.modes < auto.n_free and not math.isfinite(auto.bound)
    runs = (("analytic-all", {}),
            ("analytic", {"times": case.times, **({"modes": auto.modes} if finer
                                                   else {"tolerance": target})}))
    if best is not None:
        runs += (("radau7", {"method": "radau7", "times": case.times,
                             "substeps": substeps(best)}),)
    out = []
    for solver, options in runs:
        def read() -> np.ndarray:
            model = case.fresh_model()
            return model.dynamic(case.load, case.t_end, **options).displacement(case.times, u, v)
        seconds, values = median_run(read)
        error = float(np.abs(values - reference).max()) / scale
        twin = next(r for r in nets_rows if r.solver == solver)
        status = "exact" if solver == "analytic-all" else "ok"
        out.append(Row("clamped", cells, case.model.n_free, solver, status, seconds,
                       error=error if solver != "analytic-all" else math.nan,
                       setting=twin.setting, runs=1, modes=twin.modes, bound=twin.bound,
                       note="from scratch; displacement of the probes at every frame"))
    return nets_rows + _tag(out, "probes", f"{len(PROBES)} probes")


def run(study: Any, say: Callable[[str], None], quick: bool = False) -> list[Row]:
    """All regimes b–e at the study's target; ``quick`` uses tiny nets (structure only)."""
    target = study.target
    small, big = (4, 6) if quick else (16, 64)
    budget = study.budget
    frames = 20 if quick else 200
    rows: list[Row] = []
    horizons = (1, 3) if quick else (1, 10, 100, 1000)
    passing: dict[tuple[str, float], int] = {}
    for damping in ("light", "heavy"):
        start = 0
        for periods in horizons:
            say(f"horizon: {damping} damping, {periods} periods, {small}×{small}")
            line, best = horizon(small, periods, damping, frames, target, budget, start)
            rows += line
            say("    " + _summary(line))
            if best is not None:
                passing[damping, periods] = best
            # light damping: steps per period stay, so steps per frame grow with the
            # horizon (×10 ≈ six levels of √2); heavy damping: far slower
            grow = 6 if damping == "light" else 2
            start = best + grow if best is not None else start + grow + 2
    goal_cells, goal_periods = (6, 3) if quick else (32, 100)
    say(f"horizon: light damping, {goal_periods} periods, {goal_cells}×{goal_cells} (goal)")
    line, _ = horizon(goal_cells, goal_periods, "light", frames, target,
                      study.budget_for(goal_cells) if quick else 5 * budget,
                      passing.get(("light", goal_periods), -2) + 2)
    rows += line
    say("    " + _summary(line))
    mid = 6 if quick else 32
    say(f"each additional load case, {mid}×{mid}")
    rows += (line := load_case(mid, frames, target, budget))
    say("    " + _summary(line))
    say(f"one state at one time, {big}×{big}")
    rows += (line := one_state(big, target, study.budget_for(big)))
    say("    " + _summary(line))
    say(f"probes against whole nets, {mid}×{mid}")
    rows += (line := probes(mid, frames, target, budget))
    say("    " + _summary(line))
    return rows


def _summary(rows: list[Row]) -> str:
    parts = []
    for r in rows:
        cost = r.seconds if math.isfinite(r.seconds) else r.estimate
        parts.append(f"{r.case + ': ' if r.regime == 'probes' else ''}{r.solver} "
                     f"{cost:.3g} s" + ("" if r.status in ("ok", "exact") else f" ({r.status})"))
    return ", ".join(parts)

