"""Rows of the cost study and what is derived from them: the fastest method of a line,
ratios against it, runs stopped at the budget and forecasts of runs not made, cost slopes.

Every line of every regime is a set of :class:`Row` sharing ``regime`` and ``case`` (and
``family``, ``cells``). A row's ``ratio`` is its time (or its extrapolated time) over the
time of the *fastest* finished run of its line, so the fastest has ratio 1 and every other
says by how much it is slower.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from .cases import Case
from .timing import Attempt

MIN_PROGRESS = 0.05
"""A run stopped before this fraction of ``t_end`` is not extrapolated (start-up dominates)."""
ANALYTIC = ("analytic", "analytic-all")
"""Solver names of the analytic rows: automatic mode count, and all modes."""


@dataclass
class Row:
    """One result: a solver on one line (regime, case) of the study."""

    family: str
    cells: int
    n_free: int
    solver: str
    status: str                 # exact | ok | not reached | over budget | skipped | not run
    seconds: float = math.nan   # assembly + solution + frames
    setup: float = math.nan     # analytic: assembly + eigen + modal set-up
    per_frame: float = math.nan
    error: float = math.nan
    setting: str = ""
    estimate: float = math.nan  # extrapolated seconds when stopped, skipped or not run
    ratio: float = math.nan     # seconds (or estimate) / seconds of the fastest of the line
    runs: int = 0
    progress: float = math.nan  # fraction of t_end simulated when stopped at the budget
    note: str = ""
    regime: str = "size"
    case: str = ""
    modes: int = 0              # analytic: modes used (0: all)
    bound: float = math.nan     # analytic, automatic: the a-priori bound reached

    @property
    def line(self) -> tuple[str, str, str, int]:
        return (self.regime, self.case, self.family, self.cells)

    @property
    def analytic(self) -> bool:
        return self.solver in ANALYTIC

    @property
    def cost(self) -> float:
        """Measured seconds of a finished run, else the extrapolated or forecast seconds."""
        return self.seconds if self.status in ("ok", "exact") else self.estimate


def finished(row: Row) -> bool:
    return row.status in ("ok", "exact") and math.isfinite(row.seconds)


def fastest(rows: Sequence[Row]) -> Row | None:
    """The quickest finished run (analytic or numerical at its passing setting) of a line."""
    done = [r for r in rows if finished(r)]
    return min(done, key=lambda r: r.seconds) if done else None


def fastest_estimate(rows: Sequence[Row]) -> Row | None:
    """A run stopped at the budget whose extrapolated cost beats every finished run, if any.

    Only runs that simulated at least :data:`MIN_PROGRESS` of ``t_end`` count, so a method
    that is probably faster is not hidden behind the budget.
    """
    best = fastest(rows)
    stopped = [r for r in rows if r.status == "over budget" and math.isfinite(r.estimate)
               and r.progress >= MIN_PROGRESS]
    quick = min(stopped, key=lambda r: r.estimate) if stopped else None
    if quick is not None and (best is None or quick.estimate < best.seconds):
        return quick
    return None


def set_ratios(rows: Sequence[Row]) -> None:
    """Fill every row's ``ratio``: its cost over the fastest finished cost of its line.

    A run stopped at the budget too early to be extrapolated gets its measured seconds over
    the fastest (a lower bound); rows without any cost keep NaN.
    """
    lines: dict[tuple, list[Row]] = {}
    for r in rows:
        lines.setdefault(r.line, []).append(r)
    for line in lines.values():
        best = fastest(line)
        for r in line:
            cost = r.cost
            if not math.isfinite(cost) and r.status == "over budget":
                cost = r.seconds
            r.ratio = cost / best.seconds if best is not None and math.isfinite(cost) else math.nan


def numerical_row(case: Case, method: str, tried: dict[int, Attempt], best: int | None,
                  assembly: float, label: str) -> Row:
    """Summarise a setting search as a row (``label``: the setting text of the best level)."""
    from .search import setting_label

    row = Row(case.family, case.cells, case.model.n_free, method, "not reached",
              runs=len(tried))
    if best is not None:
        a = tried[best]
        row.status, row.seconds, row.error, row.setting = "ok", assembly + a.seconds, a.error, label
        return row
    stopped = [a for a in tried.values() if a.stopped]
    if stopped:
        a = stopped[-1]
        row.status, row.seconds = "over budget", assembly + a.seconds
        row.setting = setting_label(method, a.level)
        row.progress = a.progress
        row.note = f"stopped after {a.seconds:.0f} s at {a.progress:.1%} of t_end"
        if a.progress >= MIN_PROGRESS:
            row.estimate = assembly + a.estimate
            row.note += "; full run extrapolated"
        else:
            row.note += "; too early to extrapolate (the ratio is a lower bound)"
    finished_runs = [a for a in tried.values() if not a.stopped]
    if finished_runs:
        row.error = min(a.error for a in finished_runs)
        if not stopped:
            row.setting = setting_label(method, max(a.level for a in finished_runs))
            row.note = "finest setting tried"
    return row


def predicted_seconds(history: list[Row], n_free: int) -> float:
    """Cost extrapolated from the previous sizes: the power of the last two (in [1, 3]), else n¹.

    With a single smaller net the forecast is linear in ``n_free`` (small nets are dominated
    by fixed costs, so a steeper guess would skip methods that still fit the budget).
    """
    done = [r for r in history if math.isfinite(r.cost)]
    if not done:
        return 0.0
    cost = [r.cost for r in done]
    power = 1.0
    if len(done) >= 2 and done[-1].n_free > done[-2].n_free:
        power = math.log(cost[-1] / cost[-2]) / math.log(done[-1].n_free / done[-2].n_free)
        power = min(max(power, 1.0), 3.0)
    return cost[-1] * (n_free / done[-1].n_free) ** power


def skip_row(case: Case, method: str, history: list[Row], budget: float) -> Row | None:
    """A 'skipped' row when a smaller net already exceeded the budget or the forecast is > 4× it."""
    if not history:
        return None
    last = history[-1]
    if last.status in ("over budget", "skipped"):
        predicted = (predicted_seconds(history, case.model.n_free)
                     if math.isfinite(last.estimate) else math.nan)
        over = next((r for r in history if r.status == "over budget"), last)
        return Row(case.family, case.cells, case.model.n_free, method, "skipped",
                   estimate=predicted,
                   note=f"over the budget on the {over.cells}×{over.cells} net"
                   + ("; forecast" if math.isfinite(predicted) else ""))
    predicted = predicted_seconds(history, case.model.n_free)
    if predicted > 4 * budget:
        return Row(case.family, case.cells, case.model.n_free, method, "skipped",
                   estimate=predicted, note=f"forecast {predicted:.0f} s > 4× the {budget:g} s budget")
    return None


def fitted_slope(rows: list[Row], key: str = "seconds", largest: int = 3) -> float:
    """Least-squares slope ``p`` of ``log(time) = p log(n_free) + c`` over the ``largest`` nets.

    Uses measured times and, for ``seconds``, the extrapolations of runs stopped at the budget
    (not the forecasts of skipped or not-run rows, which come from a slope already).
    """
    points = []
    for r in rows:
        value = getattr(r, key)
        if r.status == "over budget" and key == "seconds":
            value = r.estimate
        elif r.status not in ("ok", "exact"):
            continue
        if math.isfinite(value) and value > 0:
            points.append((r.n_free, value))
    use = sorted(points)[-largest:]
    if len({p[0] for p in use}) < 2:
        return math.nan
    x, y = np.log([p[0] for p in use]), np.log([p[1] for p in use])
    return float(np.polyfit(x, y, 1)[0])


def power_forecast(rows: list[Row], n_free: int, key: str = "seconds") -> tuple[float, float]:
    """Cost at ``n_free`` from the slope of the two largest finished nets: ``(seconds, p)``."""
    points = sorted((r.n_free, getattr(r, key)) for r in rows
                    if r.status in ("ok", "exact") and math.isfinite(getattr(r, key)))
    if len(points) < 2 or points[-1][0] == points[-2][0]:
        return math.nan, math.nan
    (n1, t1), (n2, t2) = points[-2:]
    p = math.log(t2 / t1) / math.log(n2 / n1)
    return t2 * (n_free / n2) ** p, p
