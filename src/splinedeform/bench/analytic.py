"""The analytic rows of the study: the default call, all modes, and the reference nets.

* ``analytic`` (the headline row): the README's call as it ships,
  ``Model.dynamic(load, t_end)`` and then ``solution.control_points(frames)`` — no
  ``times=``, no ``tolerance=``, no thread pinning by the study: the library chooses the
  lowest modes plus the exact static part of the rest for its default accuracy
  (``1e-8`` of the largest static displacement in the largest control-point coordinate, at
  any time; all modes on small or separable nets) and runs its solves with its own BLAS
  thread setting (:mod:`splinedeform.threads`). Its row reports the modes used, the bound
  reached and the error measured against the reference.
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

from ..modal_solve import DEFAULT_TOLERANCE
from .bookkeeping import Row, power_forecast
from .cases import Case, relative_error
from .timing import median_run

DENSE_LIMIT = 4000
"""All-modes rows run up to this many free coordinates (64²: 3969)."""
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
        _, nets, setup, frames = _solve(case, modes="all")
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


def automatic(case: Case, target: float, repeats: int = 3, times_given: bool = False) -> Row:
    """The README's call as it ships: ``Model.dynamic(load, t_end)``, then
    ``solution.control_points(frames)``, with the library's own thread setting.

    No ``tolerance=``: the library chooses its modes for its default accuracy
    (:data:`splinedeform.modal_solve.DEFAULT_TOLERANCE`), so the row reports the error
    measured against the reference next to ``target``, the modes the default chose and its
    bound; nothing is retried. The modes are chosen for any time in ``[0, t_end]``, or with
    ``times_given`` for the case's times, passed as ``dynamic(..., times=...)`` (the call for
    one state, docs/cost.md).
    """
    options = {"times": case.times} if times_given else {}
    solution, nets, setup, frames = _solve(case, **options)
    error = relative_error(nets, case)
    report = _truncation(solution)
    modes = int(solution.basis.size)
    bound = float(report.get("bound", 0.0 if modes >= case.model.n_free else math.nan))
    tolerance = float(report.get("tolerance", DEFAULT_TOLERANCE))
    row = Row(case.family, case.cells, case.model.n_free, "analytic",
              "ok" if error <= target else "not reached", error=error, modes=modes,
              bound=bound, runs=1)
    row.setting = ("default call, times given, " if times_given else "default call, ") + \
        automatic_label(tolerance, modes, bound, case.model.n_free)
    runs = [(setup + frames, setup, frames)]
    while runs[0][0] < 3.0 and len(runs) < repeats:
        _, _, s, f = _solve(case, **options)
        runs.append((s + f, s, f))
    row.seconds, row.setup, frames = sorted(runs)[len(runs) // 2]
    row.per_frame = frames / case.times.size
    row.runs = len(runs)
    return row


def automatic_label(tolerance: float, modes: int, bound: float, n_free: int) -> str:
    """``tolerance 1e-06: 256 modes, bound 2.1e-07`` (or all modes when the bound needed them)."""
    if not modes or modes >= n_free:
        return (f"tolerance {tolerance:g}: all modes (a small or separable net, or a "
                "truncated basis would need ≥ n/2)")
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
