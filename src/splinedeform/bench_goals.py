"""Regimes of the cost study beyond cost against net size, and the goals measured in them.

Each regime compares the analytic path with Radau IIA-7 (the strongest integrator: exact
stage solves, LUs reused, only the moving coordinate) at its cheapest setting reaching the
target (steps per frame interval a factor √2 apart, :func:`splinedeform.bench.search`):

* horizon: ``periods`` periods of the lowest mode, light (``γ = 0.05, β = 0``) or the bench
  plate's damping, 200 frames;
* load cases: a second load case on a model already solved, against a full integrator run;
* one state: the displacement at a single arbitrary time ``t = 0.37 t_end`` from scratch
  (assembly, eigen-solution), against integrating to ``t``.

BLAS runs on one thread (:func:`blas_threads`): complex sparse LUs and the dense ``eigh``
stall erratically with two OpenBLAS threads on a loaded 2-core machine.
"""

from __future__ import annotations

import contextlib
import math
import statistics
import time
from collections.abc import Callable, Iterator
from dataclasses import replace
from typing import Any

import numpy as np

from . import bench, loads
from .material import Material

LIGHT = replace(bench.PLATE, damping=0.05, rayleigh=0.0)


@contextlib.contextmanager
def blas_threads(n: int = 1) -> Iterator[str]:
    """Limit BLAS/OpenMP threads to ``n`` (threadpoolctl); yields the setting as text."""
    try:
        from threadpoolctl import threadpool_limits
    except ImportError:                                         # pragma: no cover
        yield "BLAS threads not controlled (threadpoolctl missing)"
        return
    with threadpool_limits(limits=n):
        yield f"BLAS threads limited to {n} (threadpoolctl)"


def _case(cells: int, material: Material, t_end: float, times: np.ndarray,
          load: loads.Load | None = None) -> bench.Case:
    model = bench.build_model("clamped", cells, material)
    return bench.Case("clamped", cells, model, load or bench.study_load(t_end), t_end, times)


def _reference(case: bench.Case) -> float:
    """Fill the case's analytic reference; return the analytic seconds (median of 3 fresh)."""
    runs = []
    for i in range(3):
        model = case.model if i == 0 else bench.build_model("clamped", case.cells,
                                                            case.model.material)
        start = time.perf_counter()
        nets = model.dynamic(case.load, case.t_end).control_points(case.times)
        runs.append(time.perf_counter() - start + model.timings["assembly"])
        if i == 0:
            case.reference = nets
            case.scale = float(np.abs(nets - model.surface.control_points).max())
    return statistics.median(runs)


def _integrator(case: bench.Case, method: str, target: float, budget: float, start: int
                ) -> dict[str, Any]:
    study = bench.Study(target=target, budget=budget)
    tried, best = bench.search(case, method, start, study)
    if best is None:
        stopped = [a for a in tried.values() if a.stopped]
        bound = max((a.seconds for a in tried.values()), default=math.nan)
        return {"method": method, "status": "over budget" if stopped else "not reached",
                "seconds": bound, "setting": "", "runs": len(tried)}
    a = tried[best]
    return {"method": method, "status": "ok", "seconds": a.seconds + case.model.timings["assembly"],
            "error": a.error, "setting": bench.setting_label(method, best), "runs": len(tried),
            "level": best}


def horizon(cells: int, periods: float, material: Material, frames: int = 200,
            target: float = 1e-6, budget: float = 120.0, start: int = 6) -> dict[str, Any]:
    """Analytic against Radau IIA-7 over ``periods`` periods of the lowest mode."""
    omega = bench.build_model("clamped", cells, material).frequencies(1)[0]
    t_end = periods * 2 * math.pi / float(omega)
    case = _case(cells, material, t_end, np.linspace(0.0, t_end, frames))
    analytic = _reference(case)
    radau = _integrator(case, "radau7", target, budget, start)
    return {"cells": cells, "periods": periods, "damping": material.damping,
            "rayleigh": material.rayleigh, "analytic_s": analytic, "radau7": radau,
            "ratio": radau["seconds"] / analytic}


def second_load_case(cells: int = 32, frames: int = 200, target: float = 1e-6,
                     budget: float = 60.0) -> dict[str, Any]:
    """A second load case on a solved model against a full Radau IIA-7 run of that case."""
    t_end = bench.reference_t_end("clamped")
    times = np.linspace(0.0, t_end, frames)
    first = _case(cells, bench.PLATE, t_end, times)
    model = first.model
    model.dynamic(first.load, t_end).control_points(times)           # the model is solved
    second = loads.Point(0.7, 0.6, (0.0, 0.0, -2.0), profile=loads.Step(0.2 * t_end))
    runs = []
    for _ in range(5):
        start = time.perf_counter()
        nets = model.dynamic(second, t_end).control_points(times)
        runs.append(time.perf_counter() - start)
    case = bench.Case("clamped", cells, model, second, t_end, times, nets,
                      float(np.abs(nets - model.surface.control_points).max()))
    radau = _integrator(case, "radau7", target, budget, 0)
    radau["seconds"] -= model.timings["assembly"]                    # the model exists
    analytic = statistics.median(runs)
    return {"cells": cells, "analytic_s": analytic, "radau7": radau,
            "ratio": radau["seconds"] / analytic}


def single_state(cells: int = 64, fraction: float = 0.37, target: float = 1e-6,
                 budget: float = 120.0) -> dict[str, Any]:
    """The state at one time ``t = fraction · t_end`` from scratch: analytic vs Radau IIA-7."""
    t_end = bench.reference_t_end("clamped")
    t = fraction * t_end
    case = _case(cells, bench.PLATE, t_end, np.array([t]))
    start = time.perf_counter()
    analytic_model = bench.build_model("clamped", cells)
    net = analytic_model.dynamic(case.load, t_end).control_points([t])
    analytic = time.perf_counter() - start
    case.reference = net
    case.scale = float(np.abs(net - case.model.surface.control_points).max())
    radau = _integrator(case, "radau7", target, budget, 6)
    return {"cells": cells, "t": t, "analytic_s": analytic, "radau7": radau,
            "ratio": radau["seconds"] / analytic}


def goals(say: Callable[[str], None] = print, quick: bool = False) -> dict[str, Any]:
    """Measure the regimes and the goals; ``quick`` uses tiny nets (structure only)."""
    out: dict[str, Any] = {}
    with blas_threads(1) as threads:
        out["threads"] = threads
        say(threads)
        small, big = (4, 6) if quick else (32, 64)
        light_periods = 3 if quick else 100
        say(f"horizon {light_periods} periods, light damping, {small}×{small}")
        out["light"] = horizon(small, light_periods, LIGHT, start=0 if quick else 16,
                               target=1e-4 if quick else 1e-6)
        say(f"    ×{out['light']['ratio']:.3g}")
        say(f"second load case, {small}×{small}")
        out["load_case"] = second_load_case(small, 20 if quick else 200,
                                            1e-4 if quick else 1e-6)
        say(f"    ×{out['load_case']['ratio']:.3g}")
        say(f"one state at one time, {big}×{big}")
        out["single"] = single_state(big, target=1e-4 if quick else 1e-6)
        say(f"    ×{out['single']['ratio']:.3g}")
        out["horizons"] = []
        for material, name in ((LIGHT, "light"), (bench.PLATE, "plate")):
            for periods in ((1, 3) if quick else (1, 10, 100)):
                if name == "light" and periods == light_periods and not quick:
                    continue
                cells = 4 if quick else 16
                say(f"horizon {periods} periods, {name} damping, {cells}×{cells}")
                row = horizon(cells, periods, material, start=0 if quick else 4,
                              target=1e-4 if quick else 1e-6, budget=60.0)
                row["name"] = name
                out["horizons"].append(row)
                say(f"    ×{row['ratio']:.3g} ({row['radau7']['setting']})")
    return out


def _goal_row(name: str, target: float, ratio: float, detail: str) -> str:
    met = "—" if not math.isfinite(ratio) else ("met" if ratio >= target else "missed")
    shown = f"×{ratio:.3g}" if math.isfinite(ratio) else "not measured"
    return f"| {name} | ≥ ×{target:g} | {shown} | {met} | {detail} |\n"


def _radau_text(r: dict[str, Any]) -> str:
    return (f"Radau IIA-7 {r['seconds']:.3g} s at {r['setting'] or r['status']}"
            + (f" (error {r['error']:.0e})" if "error" in r else ""))


def markdown(record: dict[str, Any], plate: dict[int, tuple[float, float, str]]) -> str:
    """Goals and regimes as markdown; ``plate`` maps cells to (analytic s, fastest integrator
    s, its name) of the bench plate table."""
    w = [f"BLAS setting: {record['threads']}.\n\n",
         "| goal | target | measured (integrator time / analytic time) | | what was compared |\n",
         "|---|---|---|---|---|\n"]
    for cells, target in ((32, 3.0), (64, 2.0), (128, 2.0)):
        if cells in plate:
            a, n, name = plate[cells]
            w.append(_goal_row(f"bench plate {cells}², 200 frames, 1e-6", target, n / a,
                               f"analytic {a:.3g} s vs {name} {n:.3g} s"))
        else:
            w.append(_goal_row(f"bench plate {cells}², 200 frames, 1e-6", target, math.nan,
                               "not run (see below)"))
    light, case, single = record["light"], record["load_case"], record["single"]
    w.append(_goal_row(f"light damping (γ = 0.05, β = 0), {light['periods']:g} periods, "
                       f"{light['cells']}²", 300, light["ratio"],
                       f"analytic {light['analytic_s']:.3g} s vs {_radau_text(light['radau7'])}"))
    w.append(_goal_row(f"each additional load case, {case['cells']}²", 20, case["ratio"],
                       f"analytic {case['analytic_s']:.3g} s vs {_radau_text(case['radau7'])}"))
    w.append(_goal_row(f"one state at t = {single['t']:.3g}, {single['cells']}²", 100,
                       single["ratio"], f"analytic from scratch {single['analytic_s']:.3g} s vs "
                       f"{_radau_text(single['radau7'])}"))
    w.append("\nCost against the horizon (16², 200 frames, 1e-6; the 100-period light row at "
             "32² is the goal above):\n\n| damping | periods | analytic | Radau IIA-7 | "
             "integrator / analytic |\n|---|---|---|---|---|\n")
    for h in record["horizons"]:
        w.append(f"| {h['name']} | {h['periods']:g} | {h['analytic_s']:.3g} s | "
                 f"{_radau_text(h['radau7'])} | ×{h['ratio']:.3g} |\n")
    return "".join(w)
