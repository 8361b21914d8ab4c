"""Regime a: cost against net size at a fixed horizon (ten periods, 200 frames).

Per family and net: the analytic rows (:mod:`.analytic`: automatic mode count; all modes
while affordable, else *not run* with a forecast), then every numerical method at its
cheapest setting reaching the target (:mod:`.search`), a method skipped once it exceeded the
budget on a smaller net or its forecast exceeds four budgets (:mod:`.bookkeeping`); above
64×64 only the integrator that was fastest on the previous net runs (the others are
forecast), with its own budget (``Study.large_budget``), and its search does not try the
setting that missed the target more than ten times on the previous net. The
reference is the all-modes solution, checked against DOP853 at ``rtol = 1e-12`` on the
smallest nets (at most ``YARDSTICK_CELLS`` cells per direction: beyond, that check alone
outlasts the budget four times over); where all modes are out of reach, the automatic solution at a tolerance ten
times tighter, cross-checked against Radau IIA-7 with twice its passing steps over the first
tenth of the horizon.
"""

from __future__ import annotations

import math
from collections.abc import Callable

from . import analytic
from .bookkeeping import Row, numerical_row, predicted_seconds, skip_row
from .cases import make_case
from .config import YARDSTICK_CELLS, Study
from .search import START_LEVEL, search, setting_label, substeps
from .timing import assembly_seconds, attempt

LARGE = 64
"""Above this many cells per direction only the fastest integrator of the previous net runs."""


def yardstick(case, row: Row, budget: float) -> None:
    """Compare the reference (all modes) with DOP853 at ``rtol = 1e-12`` (fills ``row.error``)."""
    tight = {"rtol": 1e-12, "atol": 1e-14 * case.scale}
    result = attempt(case, "dop853", 0, 4 * budget, tight)
    if result.stopped:
        row.note = "yardstick run (DOP853, rtol 1e-12) over budget"
        return
    row.error = result.error
    row.note = f"vs DOP853 rtol 1e-12 ({result.seconds:.1f} s)"


def study_family(family: str, study: Study, say: Callable[[str], None]) -> list[Row]:
    """All sizes and methods of one family."""
    rows: list[Row] = []
    history: dict[str, list[Row]] = {m: [] for m in study.methods}
    dense: list[Row] = []
    start_level = dict(START_LEVEL)
    leader: str | None = None
    floors: dict[str, int] = {}
    sizes = [c for c in study.sizes if family != "region" or c <= study.region_max]
    for index, cells in enumerate(sizes):
        case = make_case(family, cells, study.frames)
        budget = study.budget_for(cells)
        assembly = assembly_seconds(case)
        if case.model.n_free <= analytic.DENSE_LIMIT:
            full = analytic.all_modes(case)
            dense.append(full)
            if index < study.yardstick_sizes and cells <= YARDSTICK_CELLS:
                yardstick(case, full, budget)
            reference = None
        else:
            full = analytic.not_run(case, dense)
            reference = analytic.sparse_reference(case, study.target)
            say(f"{family} {cells}×{cells}: reference {case.reference_note} "
                f"({reference['seconds']:.3g} s)")
        auto = analytic.automatic(case, study.target)
        rows += [auto, full]
        say(f"{family} {cells}×{cells} ({case.model.n_free} free): analytic {_seconds(auto)} "
            f"({auto.setting}, error {auto.error:.1e}); all modes {_seconds(full)}")
        passing: dict[str, int] = {}
        for method in study.methods:
            row = skip_row(case, method, history[method], budget)
            if row is None and cells > LARGE and leader is not None and method != leader:
                row = _forecast(case, method, history[method], leader)
            if row is None:
                floor = floors.get(method, -1) if cells > LARGE else -1
                tried, best = search(case, method, start_level[method], _Limits(study, budget),
                                     floor)
                label = setting_label(method, best) if best is not None else ""
                row = numerical_row(case, method, tried, best, assembly, label)
                if best is not None:
                    start_level[method] = passing[method] = best
                    coarser = tried.get(best - 1)
                    if coarser is not None and coarser.error > 10 * study.target:
                        floors[method] = best - 1
                    if floor >= 0 and best - 1 == floor:
                        row.note = (f"{setting_label(method, floor)} not tried: it missed the "
                                    "target more than ten times on the previous net")
            history[method].append(row)
            rows.append(row)
            say("    " + describe(row))
        done = [history[m][-1] for m in study.methods if math.isfinite(history[m][-1].cost)]
        leader = min(done, key=lambda r: r.cost).solver if done else None
        if reference is not None:
            auto.note = _cross_checked(case, reference, passing.get("radau7"), say)
    return rows


def _forecast(case, method: str, history: list[Row], leader: str) -> Row:
    """Above :data:`LARGE` only the previous net's fastest integrator runs; the others are
    forecast from their smaller nets."""
    estimate = predicted_seconds(history, case.model.n_free) if history else math.nan
    return Row(case.family, case.cells, case.model.n_free, method, "skipped",
               estimate=estimate if estimate > 0 else math.nan,
               note=f"above {LARGE}×{LARGE} only the fastest integrator of the previous net "
               f"({leader}) runs; forecast from the smaller nets")


class _Limits:
    def __init__(self, study: Study, budget: float):
        self.target, self.budget = study.target, budget


def _cross_checked(case, reference: dict, radau_level: int | None,
                   say: Callable[[str], None]) -> str:
    """Cross-check the sparse reference with Radau IIA-7 at twice its passing steps over the
    first tenth of the horizon."""
    steps = 2 * substeps(radau_level if radau_level is not None else 2)
    check = analytic.cross_check(case, steps, case.times.size // 10 + 1)
    text = (f"reference: {case.reference_note} ({reference['seconds']:.3g} s); on the first "
            f"{check['until']:.0%} of t_end Radau IIA-7 at {steps} steps/frame differs from it "
            f"by {check['difference']:.1e} ({check['seconds']:.3g} s)")
    say("    " + text)
    return text


def _seconds(row: Row) -> str:
    if math.isfinite(row.seconds):
        return f"{row.seconds:.3g} s"
    if math.isfinite(row.estimate):
        return f"not run (≈{row.estimate:.3g} s forecast)"
    return row.status


def describe(row: Row) -> str:
    """One line of progress for a numerical row."""
    if row.status == "ok":
        return (f"{row.solver:8s} {row.setting:20s} {row.seconds:8.3g} s  error {row.error:.1e}"
                f"  ({row.runs} runs)")
    if row.status == "skipped":
        return (f"{row.solver:8s} skipped: {row.note}"
                + (f" (≈{row.estimate:.3g} s)" if math.isfinite(row.estimate) else ""))
    if row.status == "over budget":
        return (f"{row.solver:8s} {row.setting:20s} over budget: {row.note}"
                + (f", ≈{row.estimate:.3g} s" if math.isfinite(row.estimate) else ""))
    return f"{row.solver:8s} target not reached (best error {row.error:.1e}, {row.note})"
