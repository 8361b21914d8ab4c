"""The cost study: analytic against numerical solvers, and cost against net size.

Problem families (cubic B-splines, open knots, unit square, ``μ = 1``):

``clamped``
    A clamped square plate under tension: ``w10 = w01 = 10``, ``w20 = w11 = w02 = 1``,
    viscous damping ``γ = 0.8`` and Rayleigh ``β = 5·10⁻⁴``, i.e. modal damping
    ``c_i = γ + β λ_i``: 2 % in the lowest mode, under-damped up to about 100 ω₁ (above,
    the finest modes of the net are over-damped, as structural damping grows with frequency).
``region``
    The same plate with only the control points of a central disc (radius 0.35, by their
    Greville abscissae) moving: the paper's reduced set of moving control points. The
    free region is not a rectangle, so the general (dense) eigen-solution is used.

Load: a point force ``(0, 0, -1)`` at ``(u, v) = (0.4, 0.3)``, switched on at ``t = 0`` and
off at ``t_end/2``; ``t_end`` is ten periods of the lowest mode (of a 16×16 reference net);
``F`` frames at evenly spaced times. The error of a numerical run is
``max |p_num - p_ana| / max |p_ana - p_rest|`` over all frames, control points and
coordinates. Each numerical method runs at the coarsest (cheapest) setting reaching the
target (Newmark: ``dt = t_end / (250·2^k)``; ``solve_ivp``: ``rtol = 10^-(2+k)``, ``atol =
rtol · max |p_ana - p_rest|``), found by predicting from the measured error and checking the
next coarser setting while it costs less. A run that exceeds the time budget is stopped; its full cost is
extrapolated from the simulated time it reached. On the smallest nets the analytic solution
itself is compared with a DOP853 run at ``rtol = 10⁻¹²`` (the yardstick is checked, not
trusted). Times include the assembly for both; the analytic set-up (assembly, reduction,
eigen-solution, modal forces) and the per-frame cost are reported separately, as the median
of three runs when one run takes less than 3 s (numerical runs are timed once).

Besides the table the study measures the goals of the analytic path at scale (separable
256×256 and 512×512, general 128×128 with 200 modes and the static correction, playback
of a 64×64 net with a 100×100 surface sample per frame), each in a fresh process so that
its peak memory is its own.

Run it with ``splinedeform bench`` or :func:`main`.
"""

from __future__ import annotations

import csv
import io
import json
import math
import os
import platform
import resource
import time
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from . import loads
from .errors import InputError
from .export import write_text, write_with
from .material import Material
from .model import Model
from .shapes import plane
from .solvers import numeric

Array = NDArray[np.float64]
NUMERICAL = ("radau7", "radau3", "genalpha", "newmark", "rk45", "dop853", "radau", "bdf")
SUBSTEP_METHODS = ("radau7", "radau3", "genalpha")
"""Methods whose setting is a number of equal steps per frame interval, ``round(√2^k)``."""
DEFAULT_METHODS = ("radau7", "radau3", "genalpha", "radau")
FAMILIES = ("clamped", "region")
MAX_LEVEL = {"radau7": 20, "radau3": 24, "genalpha": 30, "newmark": 14, "rk45": 10,
             "dop853": 10, "radau": 10, "bdf": 10}
START_LEVEL = {"radau7": 0, "radau3": 2, "genalpha": 8, "newmark": 1, "rk45": 2, "dop853": 2,
               "radau": 2, "bdf": 2}
ORDER = {"radau7": 13, "radau3": 5, "genalpha": 2}
PLATE = Material(mass=1.0, damping=0.8, rayleigh=5e-4, w10=10.0, w01=10.0, w20=1.0, w11=1.0,
                 w02=1.0)
SEPARABLE_PLATE = replace(PLATE, w11=0.0)
FORCE_AT = (0.4, 0.3)
REGION_RADIUS = 0.35
MIN_PROGRESS = 0.05
"""A run stopped before this fraction of ``t_end`` is not extrapolated (start-up dominates)."""


@dataclass(frozen=True)
class Study:
    """Settings of the cost study.

    Parameters
    ----------
    sizes : cells per direction of the nets (square nets ``m × m``).
    frames : number of output frames ``F``.
    target : accuracy the numerical methods must reach (max relative error at the frames).
    budget : seconds allowed to one numerical run before it is stopped and extrapolated.
    methods : numerical methods compared with the analytic solution.
    families : problem families (``clamped``, ``region``).
    yardstick_sizes : the analytic solution is checked against DOP853 (``rtol = 1e-12``)
        on this many of the smallest sizes.
    goals : also measure the goals of the analytic path at scale.
    """

    sizes: tuple[int, ...] = (4, 8, 16, 32, 64)
    frames: int = 200
    target: float = 1e-6
    budget: float = 30.0
    methods: tuple[str, ...] = DEFAULT_METHODS
    families: tuple[str, ...] = FAMILIES
    yardstick_sizes: int = 2
    goals: bool = True


QUICK = Study(sizes=(4, 6), frames=20, target=1e-4, budget=5.0, goals=False)
"""The smoke run: two tiny nets, a looser target so that Newmark needs few steps."""


@dataclass
class Row:
    """One line of the results: a solver on one net."""

    family: str
    cells: int
    n_free: int
    solver: str
    status: str                 # exact | ok | not reached | over budget | skipped
    seconds: float = math.nan   # assembly + solution + frames
    setup: float = math.nan     # analytic: assembly + eigen + modal set-up
    per_frame: float = math.nan
    error: float = math.nan
    setting: str = ""
    estimate: float = math.nan  # extrapolated seconds when stopped or skipped
    ratio: float = math.nan     # numerical seconds (or estimate) / analytic seconds
    runs: int = 0
    progress: float = math.nan  # fraction of t_end simulated when stopped at the budget
    note: str = ""


@dataclass
class Case:
    """A model, its load and frame times, with the analytic reference once computed."""

    family: str
    cells: int
    model: Model
    load: loads.Load
    t_end: float
    times: Array
    reference: Array = field(default_factory=lambda: np.zeros(0))
    scale: float = 1.0


# --------------------------------------------------------------------------- problems
def region_mask(cells: int) -> NDArray[np.bool_]:
    """Fixed control points: those whose Greville point lies outside the central disc."""
    g = plane(cells=(cells, cells)).basis_u.greville()
    return (g[:, None] - 0.5) ** 2 + (g[None, :] - 0.5) ** 2 > REGION_RADIUS**2


def build_model(family: str, cells: int, material: Material = PLATE) -> Model:
    """The model of a family on an ``cells × cells`` net."""
    surface = plane(cells=(cells, cells))
    if family == "clamped":
        return Model(surface, material, boundary="clamped")
    if family == "region":
        return Model(surface, material, boundary="free", fixed=region_mask(cells))
    raise InputError(f"unknown problem family {family!r}; choose one of {FAMILIES}")


def study_load(t_end: float) -> loads.Load:
    """Point force on at ``t = 0``, off at ``t_end / 2``."""
    return loads.Point(*FORCE_AT, (0.0, 0.0, -1.0), profile=loads.Step(0.0, 0.5 * t_end))


def reference_t_end(family: str) -> float:
    """Ten periods of the lowest mode of a 16×16 net of the family."""
    omega = build_model(family, 16).frequencies(1)[0]
    return 10 * 2 * math.pi / float(omega)


def relative_error(nets: Array, case: Case) -> float:
    """``max |p - p_ana| / max |p_ana - p_rest|`` over frames, control points, coordinates."""
    err = float(np.abs(nets - case.reference).max()) / case.scale
    return err if math.isfinite(err) else math.inf


# --------------------------------------------------------------------------- analytic
def run_analytic(case: Case, repeats: int = 3) -> Row:
    """Time the analytic solution (set-up and frames separately) and keep it as the reference.

    The whole path (assembly, eigen-solution, modal set-up, frames) runs ``repeats`` times on
    freshly built models while one run takes under a few seconds, and the run of median total
    time is reported: a single outlier on a shared machine neither helps nor hurts the ratio.
    """
    timings = []
    for i in range(max(1, repeats)):
        model = case.model if i == 0 else build_model(case.family, case.cells)
        start = time.perf_counter()
        solution = model.dynamic(case.load, case.t_end)
        solve = time.perf_counter() - start
        start = time.perf_counter()
        nets = solution.control_points(case.times)
        frames = time.perf_counter() - start
        setup = model.timings["assembly"] + solve
        timings.append((setup + frames, setup, frames))
        if i == 0:
            case.reference = nets
            case.scale = float(np.abs(nets - model.surface.control_points).max())
            kind = solution.basis.kind
        if setup + frames > 3.0:
            break
    total, setup, frames = sorted(timings)[len(timings) // 2]
    return Row(case.family, case.cells, case.model.n_free, "analytic", "exact", total, setup,
               frames / case.times.size, setting=f"{kind} eigen, all modes", runs=len(timings))


# --------------------------------------------------------------------------- numerical
class OverBudget(Exception):
    """Raised inside a numerical run when its time is up."""


class _TimedForcing(numeric.ReducedForcing):
    """The reduced load, raising :class:`OverBudget` after a deadline; remembers the time reached.

    ``reached`` is the time of the *latest* call, not the largest: before stepping, the
    integrators probe the load at times spread over ``[0, t_end]`` (up to 97 % of it) to find
    the coordinates that move, so the largest time asked says nothing of the progress. The
    stepping itself asks for the load in increasing time, so the latest call is where it was
    stopped.
    """

    def __init__(self, model: Model, load: loads.Load, deadline: float):
        super().__init__(model, load)
        self.deadline = deadline
        self.reached = 0.0

    def __call__(self, t: float) -> Array:
        if time.perf_counter() > self.deadline:
            raise OverBudget
        self.reached = float(t)
        return super().__call__(t)


@dataclass
class Attempt:
    """One numerical run at one setting level."""

    level: int
    seconds: float
    error: float = math.inf
    stopped: bool = False
    estimate: float = math.nan
    progress: float = math.nan


def substeps(level: int) -> int:
    """Steps per frame interval at a level: ``round(√2^k)`` (a factor √2 between levels)."""
    return max(1, round(math.sqrt(2.0) ** level))


def options(method: str, level: int, case: Case) -> dict[str, float]:
    """Solver settings of a level: Radau IIA / gen-α ``round(√2^k)`` steps per frame,
    Newmark ``dt = t_end/(250·2^k)``, else ``rtol = 10^-(2+k)``."""
    if method in SUBSTEP_METHODS:
        return {"substeps": substeps(level)}
    if method == "newmark":
        return {"dt": case.t_end / (250 * 2**level)}
    rtol = 10.0 ** -(2 + level)
    return {"rtol": rtol, "atol": rtol * case.scale}


def setting_label(method: str, level: int) -> str:
    if method in SUBSTEP_METHODS:
        return f"{substeps(level)} steps/frame"
    if method == "newmark":
        return f"dt = t_end/{250 * 2**level}"
    return f"rtol = 1e-{2 + level:02d}"


def attempt(case: Case, method: str, level: int, budget: float,
            opts: dict[str, float] | None = None) -> Attempt:
    """Run ``method`` once at ``level`` (or explicit ``opts``); stop it after ``budget`` seconds."""
    model = case.model
    zeros = np.zeros((model.n_free, 3))
    start = time.perf_counter()
    forcing = _TimedForcing(model, case.load, start + budget)
    try:
        sol = numeric.integrate(model, forcing, method, case.t_end, case.times, zeros, zeros,
                                **(opts or options(method, level, case)))
    except OverBudget:
        elapsed = time.perf_counter() - start
        reached = max(forcing.reached, 1e-3 * case.t_end)
        return Attempt(level, elapsed, stopped=True, estimate=elapsed * case.t_end / reached,
                       progress=forcing.reached / case.t_end)
    except InputError:                      # the integrator gave up: treat as inaccurate
        return Attempt(level, time.perf_counter() - start)
    seconds = time.perf_counter() - start
    return Attempt(level, seconds, relative_error(sol.control_points(case.times), case))


def next_level(method: str, level: int, error: float, target: float) -> int:
    """Predicted finer level: order 2 for Newmark (error ∝ dt²), ``p`` for Radau IIA and
    gen-α (error ∝ h^p, a factor √2^p per level), error ∝ rtol otherwise."""
    ratio = error / target if math.isfinite(error) else 1e6
    per_level = 4.0 if method == "newmark" else 10.0
    if method in ORDER:
        per_level = math.sqrt(2.0) ** ORDER[method]
    jump = math.ceil(math.log(max(ratio, 1.0) * 1.2) / math.log(per_level))
    return level + min(max(jump, 1), 3)


def search(case: Case, method: str, start: int, study: Study
           ) -> tuple[dict[int, Attempt], int | None]:
    """Cheapest level reaching ``study.target``.

    From ``start``, failing levels jump to the predicted finer level; a passing level is
    followed by the next coarser one until that fails, or no longer costs less (explicit
    methods on stiff nets take the steps their stability allows whatever the tolerance).
    Returns all attempts and the cheapest passing level (``None`` if none passed).
    """
    tried: dict[int, Attempt] = {}
    level = start
    while 0 <= level <= MAX_LEVEL[method]:
        result = tried[level] = attempt(case, method, level, study.budget)
        if result.stopped:
            break
        if result.error <= study.target:
            finer = tried.get(level + 1)
            not_cheaper = (finer is not None and finer.error <= study.target
                           and result.seconds >= 0.9 * finer.seconds)
            if level == 0 or level - 1 in tried or not_cheaper:
                break
            level -= 1
        else:
            if level + 1 in tried:
                break
            level = next_level(method, level, result.error, study.target)
    good = [lv for lv, a in tried.items() if a.error <= study.target]
    return tried, (min(good, key=lambda lv: tried[lv].seconds) if good else None)


def numerical_row(case: Case, method: str, tried: dict[int, Attempt], best: int | None,
                  analytic: Row) -> Row:
    """Summarise a search as a table row."""
    assembly = case.model.timings["assembly"]
    row = Row(case.family, case.cells, case.model.n_free, method, "not reached",
              runs=len(tried))
    if best is not None:
        a = tried[best]
        row.status, row.seconds, row.error = "ok", assembly + a.seconds, a.error
        row.setting = setting_label(method, best)
        row.ratio = row.seconds / analytic.seconds
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
            row.ratio = row.estimate / analytic.seconds
            row.note += "; full run extrapolated"
        else:
            row.ratio = row.seconds / analytic.seconds       # a lower bound
            row.note += "; too early to extrapolate (the ratio is a lower bound)"
    finished = [a for a in tried.values() if not a.stopped]
    if finished:
        row.error = min(a.error for a in finished)
        if not stopped:
            row.setting = setting_label(method, max(a.level for a in finished))
            row.note = "finest setting tried"
    return row


def predicted_seconds(history: list[Row], n_free: int) -> float:
    """Cost extrapolated from the previous sizes: the power of the last two (in [1, 3]), else n¹.

    With a single smaller net the forecast is linear in ``n_free`` (small nets are dominated
    by fixed costs, so a steeper guess would skip methods that still fit the budget).
    """
    done = [r for r in history if math.isfinite(r.seconds if r.status == "ok" else r.estimate)]
    if not done:
        return 0.0
    cost = [r.seconds if r.status == "ok" else r.estimate for r in done]
    power = 1.0
    if len(done) >= 2 and done[-1].n_free > done[-2].n_free:
        power = math.log(cost[-1] / cost[-2]) / math.log(done[-1].n_free / done[-2].n_free)
        power = min(max(power, 1.0), 3.0)
    return cost[-1] * (n_free / done[-1].n_free) ** power


def skip_row(case: Case, method: str, history: list[Row], budget: float, analytic: Row
             ) -> Row | None:
    """A 'skipped' row when a smaller net already exceeded the budget or the forecast is > 4× it."""
    if not history:
        return None
    last = history[-1]
    if last.status in ("over budget", "skipped"):
        predicted = (predicted_seconds(history, case.model.n_free)
                     if math.isfinite(last.estimate) else math.nan)
        return Row(case.family, case.cells, case.model.n_free, method, "skipped",
                   estimate=predicted, ratio=predicted / analytic.seconds,
                   note=f"over the budget on the {last.cells}×{last.cells} net"
                   + ("; forecast" if math.isfinite(predicted) else ""))
    predicted = predicted_seconds(history, case.model.n_free)
    if predicted > 4 * budget:
        return Row(case.family, case.cells, case.model.n_free, method, "skipped",
                   estimate=predicted, ratio=predicted / analytic.seconds,
                   note=f"forecast {predicted:.0f} s > 4× the {budget:g} s budget")
    return None


def yardstick(case: Case, analytic: Row, budget: float) -> None:
    """Compare the analytic solution with DOP853 at ``rtol = 1e-12`` (fills ``analytic.error``)."""
    tight = {"rtol": 1e-12, "atol": 1e-14 * case.scale}
    result = attempt(case, "dop853", 0, 4 * budget, tight)
    if result.stopped:
        analytic.note = "yardstick run (DOP853, rtol 1e-12) over budget"
        return
    analytic.error = result.error
    analytic.note = f"vs DOP853 rtol 1e-12 ({result.seconds:.1f} s)"


# --------------------------------------------------------------------------- the study
def study_family(family: str, study: Study, say: Callable[[str], None]) -> list[Row]:
    """All sizes and methods of one family."""
    rows: list[Row] = []
    t_end = reference_t_end(family)
    times = np.linspace(0.0, t_end, study.frames)
    history: dict[str, list[Row]] = {m: [] for m in study.methods}
    start_level = dict(START_LEVEL)
    for index, cells in enumerate(study.sizes):
        model = build_model(family, cells)
        case = Case(family, cells, model, study_load(t_end), t_end, times)
        analytic = run_analytic(case)
        if index < study.yardstick_sizes:
            yardstick(case, analytic, study.budget)
        rows.append(analytic)
        say(f"{family} {cells}×{cells} ({model.n_free} free): analytic {analytic.setup:.3g} s "
            f"set-up + {1e3 * analytic.per_frame:.3g} ms/frame"
            + (f", vs DOP853 1e-12: {analytic.error:.1e}" if math.isfinite(analytic.error) else ""))
        for method in study.methods:
            row = skip_row(case, method, history[method], study.budget, analytic)
            if row is None:
                tried, best = search(case, method, start_level[method], study)
                row = numerical_row(case, method, tried, best, analytic)
                if best is not None:
                    start_level[method] = best
            history[method].append(row)
            rows.append(row)
            say("    " + describe(row))
    return rows


def describe(row: Row) -> str:
    """One line of progress for a numerical row."""
    if row.status == "ok":
        return (f"{row.solver:8s} {row.setting:20s} {row.seconds:8.3g} s  error {row.error:.1e}"
                f"  ({row.ratio:.3g}× analytic, {row.runs} runs)")
    if row.status == "skipped":
        return (f"{row.solver:8s} skipped: {row.note}"
                + (f" (≈{row.estimate:.3g} s)" if math.isfinite(row.estimate) else ""))
    if row.status == "over budget":
        return (f"{row.solver:8s} {row.setting:20s} over budget: {row.note}"
                + (f", ≈{row.estimate:.3g} s" if math.isfinite(row.estimate) else ""))
    return f"{row.solver:8s} target not reached (best error {row.error:.1e}, {row.note})"


# --------------------------------------------------------------------------- goals at scale
def _peak_rss_gib() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 2**20


def goal_all_modes(cells: int, frames: int, material: Material = SEPARABLE_PLATE) -> dict:
    """Assembly, all modes and ``frames`` control nets of a clamped plate (separable if w11 = 0)."""
    t_end = reference_t_end("clamped")
    start = time.perf_counter()
    model = build_model("clamped", cells, material)
    solution = model.dynamic(study_load(t_end), t_end)
    setup = time.perf_counter() - start
    t0 = time.perf_counter()
    nets = solution.control_points(np.linspace(0.0, t_end, frames))
    frame_time = time.perf_counter() - t0
    return {"cells": cells, "n_free": model.n_free, "eigensolver": solution.basis.kind,
            "modes": solution.basis.size, "setup_s": setup, "frames_s": frame_time,
            "total_s": setup + frame_time, "frames": int(nets.shape[0]),
            "peak_rss_gib": _peak_rss_gib()}


def goal_lowest_modes(cells: int, modes: int, frames: int) -> dict:
    """Lowest ``modes`` modes of the general (w11 ≠ 0) clamped plate, static correction, frames."""
    t_end = reference_t_end("clamped")
    start = time.perf_counter()
    model = build_model("clamped", cells)
    solution = model.dynamic(study_load(t_end), t_end, modes=modes)
    setup = time.perf_counter() - start
    t0 = time.perf_counter()
    solution.control_points(np.linspace(0.0, t_end, frames))
    frame_time = time.perf_counter() - t0
    report = {k: v for k, v in solution.truncation.items()}
    return {"cells": cells, "n_free": model.n_free, "modes": modes, "setup_s": setup,
            "eigen_s": model.timings.get("eigen", math.nan), "frames_s": frame_time,
            "frames": frames, "truncation": report, "peak_rss_gib": _peak_rss_gib()}


def goal_playback(cells: int, resolution: int, frames: int, modes: int = 200) -> dict:
    """Frames per second of control nets plus a ``resolution²`` surface sample (general plate).

    With all modes (dense ``Φ``) frame by frame and in one block, and with the lowest
    ``modes`` modes plus the static correction frame by frame (its largest difference to
    all modes at the frames is reported).
    """
    t_end = reference_t_end("clamped")
    model = build_model("clamped", cells)
    load = study_load(t_end)
    times = np.linspace(0.0, t_end, frames)
    out: dict[str, Any] = {"cells": cells, "n_free": model.n_free, "resolution": resolution,
                           "frames": frames, "modes": modes}
    start = time.perf_counter()
    exact = model.dynamic(load, t_end)
    out["setup_s"] = time.perf_counter() - start
    out["frame_by_frame_fps"] = _frame_rate(exact, times, resolution)
    t0 = time.perf_counter()
    exact.frames(times, resolution)
    out["bulk_fps"] = frames / (time.perf_counter() - t0)
    start = time.perf_counter()
    truncated = model.dynamic(load, t_end, modes=modes)
    out["truncated_setup_s"] = time.perf_counter() - start
    out["truncated_fps"] = _frame_rate(truncated, times, resolution)
    reference = exact.control_points(times)
    scale = float(np.abs(reference - model.surface.control_points).max())
    out["truncated_difference"] = float(np.abs(truncated.control_points(times) - reference)
                                        .max()) / scale
    out["peak_rss_gib"] = _peak_rss_gib()
    return out


def _frame_rate(solution: Any, times: Array, resolution: int) -> float:
    """Frames per second of ``solution.frames(t, resolution)`` called once per frame."""
    solution.frames(times[:1], resolution)           # the sampling matrix, built once
    start = time.perf_counter()
    for t in times:
        solution.frames(t, resolution)
    return times.size / (time.perf_counter() - start)


def in_fresh_process(function: Callable[..., dict], *args: Any) -> dict:
    """Run a goal in a new interpreter (its own peak memory); errors come back as a note."""
    import concurrent.futures
    import multiprocessing

    context = multiprocessing.get_context("spawn")
    with concurrent.futures.ProcessPoolExecutor(max_workers=1, mp_context=context) as pool:
        try:
            return pool.submit(function, *args).result()
        except Exception as exc:  # noqa: BLE001 - reported in the table, not raised
            return {"error": f"{type(exc).__name__}: {exc}"}


@dataclass
class Goal:
    """A goal line: what was asked, what was measured, whether it holds."""

    name: str
    target: str
    measured: str
    met: bool | None
    limit: str = ""


def ratio_goal(rows: list[Row], frames: int, target: float) -> Goal:
    """32×32 clamped plate: fastest numerical method / analytic, at the study's accuracy."""
    name = f"32×32 cells, {frames} frames, accuracy {target:g}: analytic vs fastest numerical"
    analytic = [r for r in rows if r.family == "clamped" and r.cells == 32 and r.solver == "analytic"]
    if not analytic:
        return Goal(name, "≥ 100×", "not measured (32 not among the sizes)", None)
    numerical = [r for r in rows if r.family == "clamped" and r.cells == 32
                 and r.solver != "analytic"]
    done = [r for r in numerical if r.status == "ok"]
    if done:
        best = min(done, key=lambda r: r.seconds)      # stopped runs took longer than this
        text = (f"{best.ratio:.0f}× ({best.solver} {best.seconds:.3g} s vs analytic "
                f"{analytic[0].seconds:.3g} s)")
        return Goal(name, "≥ 100×", text, best.ratio >= 100)
    stopped = [r for r in numerical if r.status in ("over budget", "skipped")]
    if not stopped:
        return Goal(name, "≥ 100×", "no numerical method reached the accuracy", None)
    lower = min((r.seconds for r in stopped if math.isfinite(r.seconds)), default=math.nan)
    bound = lower / analytic[0].seconds
    measured = f"≥ {bound:.0f}× measured" if math.isfinite(bound) else ""
    estimated = [r for r in stopped if math.isfinite(r.estimate)]
    if not estimated:
        return Goal(name, "≥ 100×", f"every numerical run exceeded the budget: {measured}",
                    bound >= 100 if math.isfinite(bound) else None)
    best = min(estimated, key=lambda r: r.estimate)
    text = (f"≈{best.ratio:.0f}× extrapolated ({best.solver} ≈{best.estimate:.3g} s vs analytic "
            f"{analytic[0].seconds:.3g} s); every numerical run exceeded the budget"
            + (f", so {measured}" if measured else ""))
    return Goal(name, "≥ 100×", text, best.ratio >= 100)


def scale_goals(say: Callable[[str], None]) -> tuple[list[Goal], dict[str, dict]]:
    """The goals of the analytic path at scale, each in a fresh process."""
    goals, raw = [], {}
    say("goal: separable 256×256, all modes + 100 frames")
    raw["separable_256"] = r = in_fresh_process(goal_all_modes, 256, 100)
    goals.append(_timed_goal("separable 256×256 cells, all modes + 100 frames", r, "total_s",
                             10.0, "< 10 s"))
    say("goal: separable 512×512, all modes + 100 frames")
    raw["separable_512"] = r = in_fresh_process(goal_all_modes, 512, 100)
    if "error" in r:
        goals.append(Goal("separable 512×512 cells runs within 24 GiB", "≤ 24 GiB", r["error"],
                          False))
    else:
        goals.append(Goal("separable 512×512 cells runs within 24 GiB", "≤ 24 GiB",
                          f"peak {r['peak_rss_gib']:.2f} GiB, {r['total_s']:.3g} s "
                          f"({r['n_free']} free coordinates)", r["peak_rss_gib"] <= 24))
    say("goal: general 128×128, lowest 200 modes + static correction")
    raw["general_128"] = r = in_fresh_process(goal_lowest_modes, 128, 200, 100)
    goals.append(_timed_goal("general (w11 ≠ 0) 128×128 cells, lowest 200 modes + static "
                             "correction", r, "setup_s", 30.0, "< 30 s"))
    say("goal: playback of a 64×64 net")
    raw["playback_64"] = r = in_fresh_process(goal_playback, 64, 100, 100)
    goals.append(_playback_goal(r))
    return goals, raw


def _timed_goal(name: str, r: dict, key: str, limit: float, target: str) -> Goal:
    if "error" in r:
        return Goal(name, target, r["error"], False)
    parts = f"{r[key]:.3g} s ({r['n_free']} free coordinates"
    if "truncation" in r:
        tr = r["truncation"]
        parts += (f"; eigen {r['eigen_s']:.3g} s; first omitted ω = "
                  f"{tr['omega_first_omitted']:.4g}, omitted static part "
                  f"{tr['omitted_static']:.1e}, static residual {tr['static_residual']:.1e}"
                  f"; then 100 frames {r['frames_s']:.3g} s")
    else:
        parts += f"; set-up {r['setup_s']:.3g} s, frames {r['frames_s']:.3g} s"
    return Goal(name, target, parts + ")", r[key] < limit)


def _playback_goal(r: dict) -> Goal:
    name = "64×64 net plays back (control points + 100×100 surface sample per frame)"
    if "error" in r:
        return Goal(name, "≥ 60 fps", r["error"], False)
    text = (f"all {r['n_free']} modes (set-up {r['setup_s']:.3g} s): "
            f"{r['frame_by_frame_fps']:.0f} fps frame by frame, {r['bulk_fps']:.0f} fps in "
            f"blocks of {r['frames']}; lowest {r['modes']} modes + static correction (set-up "
            f"{r['truncated_setup_s']:.3g} s): {r['truncated_fps']:.0f} fps frame by frame, "
            f"largest difference to all modes at the frames {r['truncated_difference']:.0e}")
    limit = ("" if r["frame_by_frame_fps"] >= 60 else
             "with all modes, frame by frame, each frame is one product Φ q(t) with the dense "
             f"{r['n_free']} × {r['n_free']} mode matrix ({8 * r['n_free']**2 / 2**20:.0f} MiB "
             "read per frame), bound by memory bandwidth; in blocks of frames it is one matrix "
             "product, and with the lowest modes plus the static correction Φ is "
             f"{r['n_free']} × {r['modes']}")
    best = max(r["frame_by_frame_fps"], r["bulk_fps"], r["truncated_fps"])
    return Goal(name, "≥ 60 fps", text, best >= 60, limit)


# --------------------------------------------------------------------------- outputs
def fitted_slope(rows: list[Row], key: str = "seconds", largest: int = 3) -> float:
    """Least-squares slope ``p`` of ``log(time) = p log(n_free) + c`` over the ``largest`` nets.

    Uses measured times and, for ``seconds``, the extrapolations of runs stopped at the budget
    (not the forecasts of skipped runs, which come from a slope already).
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


def machine() -> str:
    """CPU model, cores, memory and library versions."""
    import scipy

    cpu = platform.processor() or platform.machine()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
        mem = next(line for line in Path("/proc/meminfo").read_text().splitlines()
                   if line.startswith("MemTotal"))
        memory = f", {int(mem.split()[1]) / 2**20:.0f} GiB RAM"
    except (OSError, StopIteration, ValueError):
        memory = ""
    return (f"{cpu}, {os.cpu_count()} cores{memory}; Python {platform.python_version()}, "
            f"numpy {np.__version__}, scipy {scipy.__version__}")


def _fmt(value: float, unit: str = "", digits: int = 3) -> str:
    if not math.isfinite(value):
        return "—"
    return f"{value:.{digits}g}{unit}"


def fastest(rows: Sequence[Row]) -> Row | None:
    """The quickest finished run (analytic or numerical at its passing setting) of a row."""
    done = [r for r in rows if r.status in ("ok", "exact") and math.isfinite(r.seconds)]
    return min(done, key=lambda r: r.seconds) if done else None


def fastest_estimate(rows: Sequence[Row]) -> Row | None:
    """A run stopped at the budget whose extrapolated cost beats every finished run, if any.

    Only runs that simulated at least ``MIN_PROGRESS`` of ``t_end`` are extrapolated, so a
    method that is probably faster is not hidden behind the budget.
    """
    best = fastest(rows)
    stopped = [r for r in rows if r.status == "over budget" and math.isfinite(r.estimate)
               and r.progress >= MIN_PROGRESS]
    quick = min(stopped, key=lambda r: r.estimate) if stopped else None
    if quick is not None and (best is None or quick.estimate < best.seconds):
        return quick
    return None


def _cell(row: Row, best: Row | None = None) -> str:
    if row.status == "ok" and best is not None:
        return f"{_fmt(row.seconds, ' s')} (×{_fmt(row.seconds / best.seconds)}; {row.error:.0e})"
    if row.status == "ok":
        return f"{_fmt(row.seconds, ' s')} (×{_fmt(row.ratio)}; {row.error:.0e})"
    if row.status == "over budget" and not math.isfinite(row.estimate):
        return (f"> budget: {_fmt(row.seconds, ' s')} for {row.progress:.0%} of t_end "
                f"(×{_fmt(row.ratio)} and more)")
    if row.status == "over budget":
        return (f"> budget at {row.progress:.0%} of t_end, ≈{_fmt(row.estimate, ' s')} "
                f"(≈×{_fmt(row.ratio)})")
    if row.status == "skipped" and not math.isfinite(row.estimate):
        return "skipped (over budget on a smaller net)"
    if row.status == "skipped":
        return f"skipped, ≈{_fmt(row.estimate, ' s')} (≈×{_fmt(row.ratio)})"
    return f"not reached ({row.error:.0e})"


def _setting_cell(row: Row) -> str:
    if row.status in ("ok", "exact"):
        return row.setting
    if row.status == "over budget":
        return f"> budget at {row.setting}"
    return row.status


def markdown(rows: list[Row], goals: list[Goal], study: Study, seconds: float,
             machine_text: str | None = None) -> str:
    """The report: problem, one table per family, settings, slopes and goals."""
    out = io.StringIO()
    w = out.write
    w("# Cost study: analytic against numerical solution\n\n")
    w(f"Machine: {machine_text or machine()}. Study time {seconds:.0f} s.\n\n")
    w("Problem: " + _problem_text(study) + "\n\n")
    w("Cells of the numerical columns: total time (ratio to the fastest method of the row; "
      "error reached); `fastest` names that method and `analytic ×` is the analytic time over "
      "the fastest time (1 when the analytic path wins; above 1 it loses by that factor). "
      "Ratios of runs over budget are against the analytic time. `> budget`: stopped at the budget, the full run extrapolated from the "
      "simulated time reached (this assumes a uniform cost per simulated time, so it "
      "over-estimates methods whose first steps are the most expensive, like BDF and Radau "
      f"right after the load switches on; below {MIN_PROGRESS:.0%} of t_end nothing is "
      "extrapolated and the ratio is a lower bound); `skipped`: forecast from the smaller "
      "nets.\n")
    for family in study.families:
        fam = [r for r in rows if r.family == family]
        if not fam:
            continue
        w(f"\n## Family `{family}`\n\n")
        w("| cells | free | analytic set-up | per frame | analytic total | analytic check | "
          + " | ".join(study.methods) + " | fastest | analytic × |\n")
        w("|---" * (8 + len(study.methods)) + "|\n")
        for cells in study.sizes:
            here = {r.solver: r for r in fam if r.cells == cells}
            a = here.get("analytic")
            if a is None:
                continue
            check = f"{a.error:.0e}" if math.isfinite(a.error) else "—"
            best = fastest(list(here.values()))
            guess = fastest_estimate(list(here.values()))
            if guess is not None:
                lead = f"≈{guess.solver} (extrapolated) | ≈{_fmt(a.seconds / guess.estimate)} |\n"
            elif best is not None:
                lead = f"{best.solver} | {_fmt(a.seconds / best.seconds)} |\n"
            else:
                lead = "— | — |\n"
            w(f"| {cells}×{cells} | {a.n_free} | {_fmt(a.setup, ' s')} | "
              f"{_fmt(1e3 * a.per_frame, ' ms')} | {_fmt(a.seconds, ' s')} | {check} | "
              + " | ".join(_cell(here[m], best) if m in here else "—" for m in study.methods)
              + " | " + lead)
        w("\nSettings found (coarsest reaching the target) and fitted cost slopes "
          "(time ∝ n_free^p, least squares over the three largest nets measured or extrapolated from a run stopped at the budget):\n\n")
        w("| solver | " + " | ".join(f"{c}×{c}" for c in study.sizes) + " | slope p |\n")
        w("|---" * (len(study.sizes) + 2) + "|\n")
        for solver in ("analytic",) + tuple(study.methods):
            sr = [r for r in fam if r.solver == solver]
            by = {r.cells: r for r in sr}
            w(f"| {solver} | " + " | ".join(
                _setting_cell(by[c]) if c in by else "—" for c in study.sizes)
              + f" | {_fmt(fitted_slope(sr), digits=2)} |\n")
            if solver == "analytic":
                w("| analytic set-up only | " + " | ".join("" for _ in study.sizes)
                  + f" | {_fmt(fitted_slope(sr, 'setup'), digits=2)} |\n")
                w("| analytic per frame | " + " | ".join("" for _ in study.sizes)
                  + f" | {_fmt(fitted_slope(sr, 'per_frame'), digits=2)} |\n")
    if goals:
        w("\n## Goals\n\n| goal | target | measured | met |\n|---|---|---|---|\n")
        for g in goals:
            met = "—" if g.met is None else ("yes" if g.met else "no")
            w(f"| {g.name} | {g.target} | {g.measured} | {met} |\n")
        limits = [g for g in goals if g.limit]
        for g in limits:
            w(f"\n*{g.name}*: {g.limit}.\n")
    return out.getvalue()


def _problem_text(study: Study) -> str:
    m = PLATE
    return (f"cubic open-knot plate on the unit square, μ = {m.mass:g}, w10 = w01 = {m.w10:g}, "
            f"w20 = w11 = w02 = {m.w20:g}, damping γ = {m.damping:g}, Rayleigh β = "
            f"{m.rayleigh:g}; point force (0, 0, -1) at {FORCE_AT} on at t = 0, off at t_end/2; "
            f"t_end = 10 periods of the lowest mode; {study.frames} frames; accuracy target "
            f"{study.target:g} (max relative error of the control points at the frames, "
            f"against the analytic solution); budget {study.budget:g} s per numerical run. "
            "Family `clamped`: all edges clamped. Family `region`: only the control points "
            f"in the central disc of radius {REGION_RADIUS} move. Times include the assembly; "
            "the analytic times are the median of three runs when one run takes < 3 s. "
            "Analytic check: difference to DOP853 at rtol 1e-12 (smallest nets).")


CSV_FIELDS = [f for f in Row.__dataclass_fields__]


def csv_text(rows: list[Row]) -> str:
    buffer = io.StringIO()
    writer = csv.DictWriter(buffer, fieldnames=CSV_FIELDS, lineterminator="\n")
    writer.writeheader()
    for row in rows:
        writer.writerow({k: (f"{v:.6g}" if isinstance(v, float) else v)
                         for k, v in asdict(row).items()})
    return buffer.getvalue()


def plot(rows: list[Row], family: str, path: Path, methods: Sequence[str]) -> Path:
    """Log–log time against free control points, with fitted slopes in the legend."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fam = [r for r in rows if r.family == family]
    fig, ax = plt.subplots(figsize=(7, 5))
    series = [("analytic", "seconds", "analytic total", "k", "o"),
              ("analytic", "setup", "analytic set-up", "0.5", "s")]
    series += [(m, "seconds", m, None, "o") for m in methods]
    for solver, key, label, colour, marker in series:
        sr = [r for r in fam if r.solver == solver]
        ok = [r for r in sr if r.status in ("ok", "exact")]
        est = [r for r in sr if r.status in ("over budget", "skipped")]
        slope = fitted_slope(sr, key)
        text = label + (f" (p = {slope:.2f})" if math.isfinite(slope) else "")
        line, = ax.loglog([r.n_free for r in ok], [getattr(r, key) for r in ok], marker=marker,
                          color=colour, label=text)
        if est and key == "seconds":
            ax.loglog([r.n_free for r in est], [r.estimate for r in est], marker=marker,
                      linestyle=":", mfc="none", color=line.get_color())
            lower = [r for r in est if r.status == "over budget" and not math.isfinite(r.estimate)]
            ax.loglog([r.n_free for r in lower], [r.seconds for r in lower], marker="^",
                      linestyle="none", mfc="none", color=line.get_color())
    ax.set_xlabel("free control points per coordinate")
    ax.set_ylabel("time [s]")
    ax.set_title(f"{family}: cost against net size (hollow: extrapolated; △: lower bound)",
                 fontsize=10)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    write_with(path, lambda tmp: fig.savefig(tmp, format="png", dpi=110))
    plt.close(fig)
    return path


# --------------------------------------------------------------------------- entry point
def main(sizes: Sequence[int] | None = None, quick: bool = False,
         outdir: str | os.PathLike[str] = "out/bench", quiet: bool = False,
         frames: int | None = None, target: float | None = None, budget: float | None = None,
         methods: Sequence[str] | None = None, families: Sequence[str] | None = None,
         goals: bool | None = None) -> dict[str, Any]:
    """Run the cost study and write its results to ``outdir``.

    Files: ``bench.json`` (every number, see :func:`render`), ``bench.md`` (the tables and
    goals), ``bench.csv`` (one row per solver and net) and ``cost_<family>.png`` (log–log
    time against free control points with fitted slopes).

    Parameters
    ----------
    sizes : cells per direction (default 4, 8, 16, 32, 64; quick: 4, 6).
    quick : a short smoke run (:data:`QUICK`: 4×4 and 6×6 nets, 20 frames, target 1e-4,
        5 s budget, no goals at scale).
    outdir : output folder (created).
    quiet : print nothing.
    frames, target, budget, methods, families, goals : override the :class:`Study` defaults.

    Returns
    -------
    dict with ``rows`` (list of :class:`Row`), ``goals`` (list of :class:`Goal`),
    ``scale`` (raw goal measurements), ``files`` (paths written), ``study`` and ``seconds``.
    """
    study = _study(sizes, quick, frames, target, budget, methods, families, goals)
    out = Path(outdir)
    out.mkdir(parents=True, exist_ok=True)
    say: Callable[[str], None] = (lambda s: None) if quiet else (lambda s: print(s, flush=True))
    start = time.perf_counter()
    rows: list[Row] = []
    for family in study.families:
        rows += study_family(family, study, say)
    goal_list: list[Goal] = []
    raw: dict[str, dict] = {}
    if study.goals:
        goal_list.append(ratio_goal(rows, study.frames, study.target))
        more, raw = scale_goals(say)
        goal_list += more
    elapsed = time.perf_counter() - start
    record = {"study": asdict(study), "rows": [asdict(r) for r in rows],
              "goals": [asdict(g) for g in goal_list], "scale": raw, "seconds": elapsed,
              "machine": machine()}
    files = {"json": write_text(out / "bench.json", json.dumps(record, indent=1))}
    files.update(render(out))
    for g in goal_list:
        say(f"goal: {g.name}: {g.measured} [{'—' if g.met is None else ('met' if g.met else 'NOT met')}]")
    say(f"written: {', '.join(str(p) for p in files.values())}")
    return {"rows": rows, "goals": goal_list, "scale": raw, "files": files, "study": study,
            "seconds": elapsed}


def render(outdir: str | os.PathLike[str]) -> dict[str, Path]:
    """Write ``bench.md``, ``bench.csv`` and the plots from the ``bench.json`` of a study run.

    Lets the report be regenerated without measuring again.
    """
    out = Path(outdir)
    try:
        record = json.loads((out / "bench.json").read_text(encoding="utf-8"))
    except (OSError, ValueError) as exc:
        raise InputError(f"cannot read the study results {out / 'bench.json'}: {exc}") from None
    study = Study(**{k: tuple(v) if isinstance(v, list) else v
                     for k, v in record["study"].items()})
    rows = [Row(**r) for r in record["rows"]]
    goals = [Goal(**g) for g in record["goals"]]
    files = {"markdown": write_text(out / "bench.md", markdown(rows, goals, study,
                                                               record["seconds"],
                                                               record.get("machine"))),
             "csv": write_text(out / "bench.csv", csv_text(rows))}
    for family in study.families:
        files[f"plot_{family}"] = plot(rows, family, out / f"cost_{family}.png", study.methods)
    return files


def _study(sizes: Sequence[int] | None, quick: bool, frames: int | None, target: float | None,
           budget: float | None, methods: Sequence[str] | None,
           families: Sequence[str] | None, goals: bool | None) -> Study:
    study = QUICK if quick else Study()
    changes: dict[str, Any] = {}
    if sizes is not None:
        sizes = tuple(sizes)
        if not sizes or any(isinstance(s, bool) or not isinstance(s, (int, np.integer)) or s < 2
                            for s in sizes):
            raise InputError(f"sizes must be integers >= 2 (cells per direction), got {list(sizes)}")
        changes["sizes"] = tuple(sorted({int(s) for s in sizes}))
    if frames is not None:
        if int(frames) < 2:
            raise InputError(f"frames must be >= 2, got {frames}")
        changes["frames"] = int(frames)
    if target is not None:
        if not 0 < float(target) < 1:
            raise InputError(f"target must be in (0, 1), got {target}")
        changes["target"] = float(target)
    if budget is not None:
        if not float(budget) > 0:
            raise InputError(f"budget must be > 0 seconds, got {budget}")
        changes["budget"] = float(budget)
    if methods is not None:
        bad = [m for m in methods if m not in NUMERICAL]
        if bad:
            raise InputError(f"unknown numerical method(s) {bad}; choose from {NUMERICAL}")
        changes["methods"] = tuple(methods)
    if families is not None:
        bad = [f for f in families if f not in FAMILIES]
        if bad:
            raise InputError(f"unknown problem family(ies) {bad}; choose from {FAMILIES}")
        changes["families"] = tuple(families)
    if goals is not None:
        changes["goals"] = bool(goals)
    return replace(study, **changes)
