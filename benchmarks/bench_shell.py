"""What the coupled Kirchhoff–Love shell costs next to the scalar plate models.

The Scordelis–Lo roof (radius 25, length 50, 80° arc, cubic splines) on ``m × m`` cells,
solved three ways: ``parametric`` and ``intrinsic`` (thin plate under tension, curved ends
pinned, one matrix shared by x, y and z) and ``shell`` (Kirchhoff–Love, rigid diaphragms
at the curved ends, x, y and z coupled in ``3n`` unknowns). For each: the number of
unknowns, the assembly, one static solve, the lowest 10 modes (sparse Lanczos) and the
complete analytic dynamic solution (every mode by dense ``eigh``) read at 200 frames.
Times are single calls in one run (BLAS on one thread when threadpoolctl is present).

Run ``python benchmarks/bench_shell.py [--cells 8 16 24]``; it prints a markdown table.
``--goals`` measures the shell at the sizes engineers use instead, each case in a fresh
process (its own peak memory, ``ru_maxrss``): the full pinched cylinder (radius 300,
length 600, thickness 3, E = 3e6, ν = 0.3, rigid diaphragms, two opposite unit loads;
``w = 1.8248e-5`` under each) on 128 × 64 cubic cells, the assembly of the roof on 64²
cubic cells and its lowest 20 modes, against the goals 10 s and 1.5 GB, 1 s and 10 s.
The shell's calls run with the library's BLAS threads (one unless ``SPLINEDEFORM_THREADS``
says otherwise, :mod:`splinedeform.threads`). The machine's load average is printed
beside the figures, and the processor time of each case beside its wall time (on a busy
machine the wall time is mostly the wait for a core; the ratio is of the wall time).
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import time
from contextlib import nullcontext
from math import pi
from typing import Any, Callable

import numpy as np

import splinedeform as sd
from splinedeform.physics.shell import ShellMaterial
from splinedeform.physics.shell_model import AreaForce, ShellModel

FRAMES = 200
MODES = 10


def timed(call: Callable[[], Any]) -> tuple[float, Any]:
    start = time.perf_counter()
    out = call()
    return time.perf_counter() - start, out


def roof(cells: int) -> sd.Surface:
    return sd.shapes.tile(radius=25.0, angle=80 * pi / 180, length=50.0, cells=cells)


def measure(cells: int) -> list[dict[str, Any]]:
    """One row per physics: unknowns and seconds per stage."""
    surface = roof(cells)
    rows = []
    plate = sd.Material(mass=1.0, w10=1.0, w01=1.0, w20=0.01, w11=0.01, w02=0.01)
    ends = {"v0": "pinned", "v1": "pinned"}
    weight = sd.Uniform((0.0, 0.0, -1.0))
    times = np.linspace(0.0, 1.0, FRAMES)
    for physics in ("parametric", "intrinsic"):
        assembly, model = timed(lambda: sd.Model(surface, plate, boundary=ends, physics=physics))
        static, _ = timed(lambda: model.static(weight))
        modes, _ = timed(lambda: model.eigen(MODES))
        model = sd.Model(surface, plate, boundary=ends, physics=physics)  # no cached modes
        dynamic, _ = timed(lambda: model.dynamic(weight, 1.0, eigensolver="dense")
                           .control_points(times))
        rows.append({"physics": physics, "cells": cells,
                     "unknowns": f"{model.n_free} per coordinate", "assembly": assembly,
                     "static": static, "modes": modes, "dynamic": dynamic})
    material = ShellMaterial(E=4.32e8, nu=0.0, thickness=0.25)
    diaphragms = {"v0": "diaphragm", "v1": "diaphragm"}
    self_weight = AreaForce(force=(0.0, 0.0, -90.0))
    assembly, shell = timed(lambda: ShellModel(surface, material, diaphragms))
    static, _ = timed(lambda: shell.static(self_weight))
    modes, _ = timed(lambda: shell.eigen(MODES))
    dynamic, _ = timed(lambda: shell.dynamic(self_weight, 1.0).control_points(times))
    rows.append({"physics": "shell", "cells": cells, "unknowns": f"{shell.n_free} coupled",
                 "assembly": assembly, "static": static, "modes": modes, "dynamic": dynamic})
    return rows


def table(rows: list[dict[str, Any]]) -> str:
    lines = ["| cells | physics | unknowns | assembly | static | lowest 10 modes | "
             f"all modes + {FRAMES} frames |", "|---|---|---|---:|---:|---:|---:|"]
    for r in rows:
        lines.append(f"| {r['cells']}×{r['cells']} | {r['physics']} | {r['unknowns']} | "
                     f"{r['assembly']:.3g} s | {r['static']:.3g} s | {r['modes']:.3g} s | "
                     f"{r['dynamic']:.3g} s |")
    return "\n".join(lines)


#: goal name → (seconds, peak GiB or None)
GOALS = {"pinched cylinder 128×64 static": (10.0, 1.5), "roof 64² assembly": (1.0, None),
         "roof 64² lowest 20 modes": (10.0, None)}


def goal_case(name: str) -> dict[str, Any]:
    """Run one goal case in this process; seconds, peak memory and a check figure."""
    if name.startswith("pinched"):
        R, L = 300.0, 600.0
        surface = sd.shapes.cylinder(radius=R, height=L, cells=(128, 64))
        start, cpu = time.perf_counter(), time.process_time()
        model = ShellModel(surface, ShellMaterial(3e6, 0.3, 3.0),
                           {"v0": "diaphragm", "v1": "diaphragm"})
        assembled = time.perf_counter()
        load = (sd.loads.Point(0.0, L / 2, (-1.0, 0.0, 0.0))
                + sd.loads.Point(pi * R, L / 2, (1.0, 0.0, 0.0)))
        w = -model.static(load).displacement(0.0, L / 2)[0]
        seconds, cpu = time.perf_counter() - start, time.process_time() - cpu
        detail = (f"assembly {assembled - start:.2f} s, static {seconds - assembled + start:.2f}"
                  f" s; {model.n_free} unknowns; w / 1.8248e-5 = {w / 1.8248e-5:.4f}")
    else:
        surface = roof(64)
        start, cpu = time.perf_counter(), time.process_time()
        model = ShellModel(surface, ShellMaterial(E=4.32e8, nu=0.0, thickness=0.25),
                           {"v0": "diaphragm", "v1": "diaphragm"})
        seconds, cpu = time.perf_counter() - start, time.process_time() - cpu
        detail = f"{model.n_free} unknowns"
        if name.endswith("modes"):
            start, cpu = time.perf_counter(), time.process_time()
            omega = model.frequencies(20)
            seconds, cpu = time.perf_counter() - start, time.process_time() - cpu
            detail += f"; ω_1 = {omega[0]:.5g}, ω_20 = {omega[-1]:.5g}"
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 2 ** 20     # KiB → GiB
    return {"seconds": seconds, "processor seconds": cpu, "peak GiB": peak, "detail": detail}


def goals() -> str:
    """Each goal case in its own process; a markdown table with measured / goal."""
    lines = [f"load average before: {os.getloadavg()[0]:.2f}", "",
             "| case | seconds | processor s | goal | ratio | peak memory | goal | detail |",
             "|---|---:|---:|---:|---:|---:|---:|---|"]
    for name, (seconds, memory) in GOALS.items():
        out = subprocess.run([sys.executable, __file__, "--goal", name], capture_output=True,
                             text=True, check=True).stdout.strip().splitlines()[-1]
        r = json.loads(out)
        limit = f"{memory:g} GiB" if memory else "-"
        lines.append(f"| {name} | {r['seconds']:.2f} | {r['processor seconds']:.2f} | "
                     f"{seconds:g} | "
                     f"{r['seconds'] / seconds:.2f} | {r['peak GiB']:.2f} GiB | {limit} | "
                     f"{r['detail']} |")
    lines += ["", f"load average after: {os.getloadavg()[0]:.2f}"]
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cells", type=int, nargs="+", default=[8, 16, 24])
    parser.add_argument("--goals", action="store_true",
                        help="the sizes engineers use, against the goals")
    parser.add_argument("--goal", choices=list(GOALS), help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.goal:
        print(json.dumps(goal_case(args.goal)))
        return
    if args.goals:
        print(goals())
        return
    try:
        from threadpoolctl import threadpool_limits
        limit: Any = threadpool_limits(1, "blas")
    except ImportError:
        limit = nullcontext()
    with limit:
        measure(4)                      # imports and first calls, not timed
        rows = [row for cells in args.cells for row in measure(cells)]
    print(table(rows))


if __name__ == "__main__":
    main()
