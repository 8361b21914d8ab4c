"""Regime a: cost against net size at a fixed horizon (ten periods, 200 frames).

Per family and net: the analytic rows (:mod:`.analytic`: automatic mode count; all modes
while affordable, else *not run* with a forecast), then every numerical method at its
cheapest setting reaching the target (:mod:`.search`), a method skipped once it exceeded the
budget on a smaller net or its forecast exceeds four budgets (:mod:`.bookkeeping`). The
reference is the all-modes solution, checked against DOP853 at ``rtol = 1e-12`` on the
smallest nets; where all modes are out of reach, the automatic solution at a tolerance a
hundred times tighter, cross-checked against a finer Radau IIA-7 run.
"""

from __future__ import annotations

import math
from collections.abc import Callable

from . import analytic
from .bookkeeping import Row, numerical_row, skip_row
from .cases import make_case
from .config import Study
from .search import START_LEVEL, search, setting_label, substeps
from .timing import assembly_seconds, attempt


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
    sizes = [c for c in study.sizes if family != "region" or c <= study.region_max]
    for index, cells in enumerate(sizes):
        case = make_case(family, cells, study.frames)
        budget = study.budget_for(cells)
        assembly = assembly_seconds(case)
        if case.model.n_free <= analytic.DENSE_LIMIT:
            full = analytic.all_modes(case)
            dense.append(full)
            if index < study.yardstick_sizes:
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
            if row is None:
                tried, best = search(case, method, start_level[method], _Limits(study, budget))
                label = setting_label(method, best) if best is not None else ""
                row = numerical_row(case, method, tried, best, assembly, label)
                if best is not None:
                    start_level[method] = passing[method] = best
            history[method].append(row)
            rows.append(row)
            say("    " + describe(row))
        if reference is not None:
            auto.note = _cross_checked(case, reference, passing.get("radau7"), say)
    return rows


class _Limits:
    def __init__(self, study: Study, budget: float):
        self.target, self.budget = study.target, budget


def _cross_checked(case, reference: dict, radau_level: int | None,
                   say: Callable[[str], None]) -> str:
    """Cross-check the sparse reference with Radau IIA-7 at twice its passing steps."""
    steps = 2 * substeps(radau_level if radau_level is not None else 2)
    check = analytic.cross_check(case, steps)
    text = (f"reference: {case.reference_note}; against Radau IIA-7 at {steps} steps/frame "
            f"it differs by {check['difference']:.1e} ({check['seconds']:.3g} s)")
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
