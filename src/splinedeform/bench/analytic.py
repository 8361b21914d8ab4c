"""The analytic rows of the study: automatic mode count, all modes, and the reference nets.

* ``analytic`` (the headline row): ``Model.dynamic(load, t_end, times=frames,
  tolerance=tol)`` — the lowest modes plus the exact static part of the rest, as many as an
  a-priori bound of the omitted modes' response at the frames needs
  (:mod:`splinedeform.solvers.mode_count`). Like the integrators it runs at its cheapest
  setting that reaches the target: ``tolerance = target``, and while the error *measured
  against the reference* misses it (the bound is in the M-norm, the study's error is the
  largest control-point difference) √2 times more modes. Its row reports the modes used
  and the bound reached.
* ``analytic-all``: all modes (the complete eigen-solution), while ``n_free`` is at most
  :data:`DENSE_LIMIT`; beyond, a row *not run* with the cost forecast from the measured
  growth of the smaller nets. Its nets are the reference where it runs.
* Where all modes are out of reach the reference is the automatic solution at
  :data:`REFERENCE_FACTOR` × the target (its bound reported), cross-checked against a
  Radau IIA-7 run with twice the steps of the study's passing Radau IIA-7 setting over the
  first tenth of the horizon (the switch-on excites every mode; the check's error is about
  2⁻⁷ of the passing run's).

Times are from scratch (assembly included) and the median of three runs when one run takes
under three seconds.
"""

from __future__ import annotations

import math
import time
from typing import Any

from .bookkeeping import Row, power_forecast
from .cases import Case, relative_error
from .timing import median_run

DENSE_LIMIT = 4000
"""All-modes rows run up to this many free coordinates (64²: 3969)."""
TRIES = 4
REFERENCE_FACTOR = 0.1


def _solve(case: Case, **options: Any) -> tuple[Any, Any, float, float]:
    """Fresh model, ``dynamic`` and the frames: ``(solution, nets, setup s, frames s)``."""
    start = time.perf_counter()
    model = case.fresh_model()
    solution = model.dynamic(case.load, case.t_end, **options)
    setup = time.perf_counter() - start
    start = time.perf_counter()
    nets = solution.control_points(case.times)
    return solution, nets, setup, time.perf_counter() - start


def all_modes(case: Case, repeats: int = 3) -> Row:
    """All modes from scratch; the nets become the case's reference."""
    runs: list[tuple[float, float, float]] = []
    for i in range(max(1, repeats)):
        _, nets, setup, frames = _solve(case)
        runs.append((setup + frames, setup, frames))
        if i == 0:
            case.set_reference(nets, "all modes (exact up to rounding)")
        if setup + frames > 3.0:
            break
    total, setup, frames = sorted(runs)[len(runs) // 2]
    return Row(case.family, case.cells, case.model.n_free, "analytic-all", "exact", total, setup,
               frames / case.times.size, setting="all modes", runs=len(runs),
               modes=case.model.n_free)


def not_run(case: Case, smaller: list[Row]) -> Row:
    """The all-modes row beyond :data:`DENSE_LIMIT`: not run, cost forecast from ``smaller``."""
    estimate, power = power_forecast(smaller, case.model.n_free)
    note = (f"not run: all {case.model.n_free} modes need a dense eigen-solution beyond "
            f"{DENSE_LIMIT} free coordinates")
    if math.isfinite(estimate):
        note += f"; forecast ∝ n_free^{power:.2f} from the two largest nets measured"
    return Row(case.family, case.cells, case.model.n_free, "analytic-all", "not run",
               estimate=estimate, setting="all modes", note=note, modes=case.model.n_free)


def _truncation(solution: Any) -> dict[str, Any]:
    return dict(getattr(solution, "truncation", None) or {})


def automatic(case: Case, target: float, repeats: int = 3) -> Row:
    """The automatic mode count, made finer by √2 while its measured error misses ``target``.

    The first run asks ``tolerance = target``; the library picks ``k`` modes (doubling from
    32) by its bound. When the error measured against the reference misses the target, the
    next runs keep ``round(√2^j k)`` modes (``modes=``, the same mode acceleration): the same
    factor √2 between settings as the integrators' search.
    """
    settings: list[dict[str, Any]] = [{"tolerance": target}]
    tries = []
    for attempt_no in range(TRIES):
        options = settings[-1]
        solution, nets, setup, frames = _solve(case, times=case.times, **options)
        error = relative_error(nets, case)
        report = _truncation(solution)
        tries.append((options, error, setup, frames, report))
        if error <= target:
            break
        first = int(tries[0][4].get("modes", 0) or 0)
        if not first or first >= case.model.n_free // 2:
            break                                   # all modes already: nothing finer
        settings.append({"modes": int(round(first * math.sqrt(2.0) ** (attempt_no + 1)))})
    options, error, setup, frames, report = tries[-1]
    first_report = tries[0][4]
    modes = int(report.get("modes", options.get("modes", 0)) or 0)
    bound = float(first_report.get("bound", math.nan))
    row = Row(case.family, case.cells, case.model.n_free, "analytic",
              "ok" if error <= target else "not reached", error=error, modes=modes, bound=bound,
              runs=len(tries))
    row.setting = automatic_label(target, int(first_report.get("modes", 0) or 0), bound,
                                  case.model.n_free)
    if "modes" in options:
        row.setting += f"; measured error above target, so {options['modes']} modes"
        row.bound = math.nan
    if error <= target:
        runs = [(setup + frames, setup, frames)]
        while runs[0][0] < 3.0 and len(runs) < repeats:
            _, _, s, f = _solve(case, times=case.times, **options)
            runs.append((s + f, s, f))
        row.seconds, row.setup, frames = sorted(runs)[len(runs) // 2]
        row.per_frame = frames / case.times.size
        row.runs += len(runs) - 1
    if len(tries) > 1:
        row.note = ("measured error above the target with " + "; ".join(
            f"{_setting_text(t[0], t[4])}: {t[1]:.2e}" for t in tries[:-1]))
    return row


def _setting_text(options: dict[str, Any], report: dict[str, Any]) -> str:
    if "modes" in options:
        return f"{options['modes']} modes"
    return f"tolerance {options['tolerance']:g} ({report.get('modes', '?')} modes)"


def automatic_label(tolerance: float, modes: int, bound: float, n_free: int) -> str:
    """``tolerance 1e-06: 256 modes, bound 2.1e-07`` (or all modes when the bound needed them)."""
    if not modes or modes >= n_free:
        return f"tolerance {tolerance:g}: all modes (a truncated basis would need ≥ n/2)"
    return f"tolerance {tolerance:g}: {modes} modes, bound {bound:.1e}"


def sparse_reference(case: Case, target: float) -> dict[str, Any]:
    """The reference where all modes are out of reach: automatic at ``REFERENCE_FACTOR·target``."""
    tolerance = REFERENCE_FACTOR * target
    seconds, (solution, nets, _, _) = median_run(
        lambda: _solve(case, times=case.times, tolerance=tolerance), repeats=1)
    report = _truncation(solution)
    modes, bound = int(report.get("modes", 0) or 0), float(report.get("bound", math.nan))
    case.set_reference(nets, "the automatic mode count at "
                       + automatic_label(tolerance, modes, bound, case.model.n_free)
                       + " (lowest modes + exact static part of the rest)")
    return {"tolerance": tolerance, "modes": modes, "bound": bound, "seconds": seconds}


def cross_check(case: Case, substeps: int, frames: int) -> dict[str, Any]:
    """Difference of the reference to Radau IIA-7 at ``substeps`` steps per frame interval
    over the first ``frames`` frames (the switch-on, where the load excites every mode)."""
    times = case.times[:frames]
    start = time.perf_counter()
    solution = case.model.dynamic(case.load, float(times[-1]), method="radau7", times=times,
                                  substeps=substeps)
    nets = solution.control_points(times)
    difference = float(abs(nets - case.reference[:frames]).max()) / case.scale
    return {"method": "radau7", "substeps": substeps, "difference": difference,
            "seconds": time.perf_counter() - start, "until": float(times[-1] / case.t_end)}
