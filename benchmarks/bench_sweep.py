"""What a sweep saves: shared models, and cases spread over worker processes.

Two ratios, each measured in one run (no timing is asserted anywhere):

1. **Shared model.** 100 load cases (a point force at 100 places) on one clamped 32 × 32
   cell plate under tension with twist (no separable factors: the modal basis is a dense
   eigensolve), solved in closed form: ``splinedeform.sweep`` on one worker — the model and
   its modal basis built once, cluster start, tables and report included — against 100
   separate runs of the same scenarios, twice: ``pipeline.run`` in this process (each
   building its model, the interpreter and its imports already warm), and the
   ``splinedeform run`` command (a process each, as a hand-written loop runs them).
   Goal ≥ ×20.
2. **Workers.** 200 independent cases (200 tension values, one model each, 10 × 10 cells):
   ``splinedeform.sweep(workers=2)`` against ``splinedeform.sweep(workers=1)``, each on the
   local cluster it starts and stops, alternated ``--repeats`` times (the machine's other
   load drifts), their medians compared. Goal ≥ ×1.7 the throughput; it needs two idle
   cores, so the load average is printed beside it. Also printed: the seconds of the cases
   themselves on the busiest worker (their rows' ``wall_s`` summed per worker), without
   the cluster's start and stop, the workers' imports and the report. The same for 200
   cases of 32 × 32 cells (``--large``), where a case is a realistic size (its
   case a few tenths of a second, mostly its eigen-solution, against about 10 ms at
   10 × 10).

Run ``python benchmarks/bench_sweep.py [--cells 32] [--separate 100] [--commands 10]
[--repeats 3] [--large 200] [--workers-only]``;
``--separate k`` and ``--commands k`` time only ``k`` of the separate runs and say so (the
ratio then uses their mean).
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

PLATE = """\
[surface]
shape = "plane"
size = 1.0
cells = {cells}

[material]
damping = 0.5
w10 = {w10}
w01 = 1.0
w20 = 0.01
w11 = 0.01
w02 = 0.01

[boundary]
u0 = "clamped"
u1 = "clamped"
v0 = "clamped"
v1 = "clamped"

[[load]]
kind = "point"
at = [{u}, {v}]
force = [0.0, 0.0, -1.0]
profile = "step"

[solve]
kind = "dynamic"
t_end = 2.0
frames = 21
modes = 6

[output]
formats = []
resolution = 16
"""


def places(count: int) -> list[list[float]]:
    """``count`` load places on a grid inside the plate."""
    side = int(round(count ** 0.5))
    ticks = [0.1 + 0.8 * i / (side - 1) for i in range(side)]
    return [[round(u, 6), round(v, 6)] for u in ticks for v in ticks][:count]


def shared_model(folder: Path, cells: int, cases: int, separate: int, commands: int
                 ) -> dict[str, float]:
    import splinedeform as sd
    from splinedeform.pipeline import run
    from splinedeform.scenario import parse_scenario

    at = places(cases)
    (folder / "plate.toml").write_text(PLATE.format(cells=cells, w10=1.0, u=0.5, v=0.5))
    (folder / "loads.toml").write_text(
        'scenario = "plate.toml"\n[[axis]]\nkey = "load[1].at"\nvalues = '
        f"{at}\n")
    start = time.perf_counter()
    result = sd.sweep(folder / "loads.toml", folder / "out-loads", workers=1)
    swept = time.perf_counter() - start
    assert result.failed == 0 and result.models == 1, (result.failed, result.models)
    start = time.perf_counter()
    for u, v in at[:separate]:
        run(parse_scenario(PLATE.format(cells=cells, w10=1.0, u=u, v=v)))
    alone = (time.perf_counter() - start) / separate * cases
    command = str(Path(sys.executable).parent / "splinedeform")
    start = time.perf_counter()
    for i, (u, v) in enumerate(at[:commands]):
        path = folder / f"alone-{i}.toml"
        path.write_text(PLATE.format(cells=cells, w10=1.0, u=u, v=v))
        subprocess.run([command, "run", str(path), "-o", str(folder / f"alone-{i}"),
                        "--quiet"], check=True, stdout=subprocess.DEVNULL)
    by_command = (time.perf_counter() - start) / max(commands, 1) * cases
    return {"sweep_s": swept, "separate_s": alone, "ratio": alone / swept,
            "command_s": by_command, "command_ratio": by_command / swept,
            "models": result.models, "cases": len(result.rows)}


def workers(folder: Path, cases: int, cells: int = 10, repeats: int = 3
            ) -> dict[str, float]:
    """``cases`` tension values, one model each: ``sd.sweep(workers=1)`` and
    ``sd.sweep(workers=2)`` alternated ``repeats`` times (the machine's other load drifts
    between them), the medians compared. Also the seconds of the cases themselves on the
    busiest worker (their rows' ``wall_s`` summed per worker)."""
    import statistics

    import splinedeform as sd

    (folder / f"small{cells}.toml").write_text(PLATE.format(cells=cells, w10=1.0, u=0.5, v=0.5))
    (folder / f"tension{cells}.toml").write_text(
        f'scenario = "small{cells}.toml"\n[[axis]]\nkey = "material.w10"\n'
        f"range = [0.5, 5.0]\ncount = {cases}\n")
    seconds: dict[int, list[float]] = {1: [], 2: []}
    busiest: dict[int, list[float]] = {1: [], 2: []}
    for _ in range(repeats):
        for n in (1, 2):
            out = folder / f"out-{cells}-{n}"
            start = time.perf_counter()
            result = sd.sweep(folder / f"tension{cells}.toml", out, workers=n)
            seconds[n].append(time.perf_counter() - start)
            assert result.failed == 0 and result.computed == cases
            per_worker: dict[str, float] = {}
            for row in result.rows:
                per_worker[row["worker"]] = per_worker.get(row["worker"], 0.0) + row["wall_s"]
            busiest[n].append(max(per_worker.values()))
            shutil.rmtree(out)
    one, two = statistics.median(seconds[1]), statistics.median(seconds[2])
    one_run, two_run = statistics.median(busiest[1]), statistics.median(busiest[2])
    return {"one_s": one, "two_s": two, "ratio": one / two, "one_run_s": one_run,
            "two_run_s": two_run, "run_ratio": one_run / two_run,
            "runs": repeats, "cells": cells, "cases": cases}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cells", type=int, default=32)
    parser.add_argument("--load-cases", type=int, default=100)
    parser.add_argument("--separate", type=int, default=None,
                        help="separate runs timed (default: all of them)")
    parser.add_argument("--commands", type=int, default=10,
                        help="separate `splinedeform run` commands timed (default 10)")
    parser.add_argument("--independent", type=int, default=200)
    parser.add_argument("--repeats", type=int, default=3,
                        help="1-worker and 2-worker sweeps alternated this many times")
    parser.add_argument("--large", type=int, default=200,
                        help="independent 32² cases timed the same way (0: none)")
    parser.add_argument("--large-repeats", type=int, default=1,
                        help="alternations of the 32² sweeps (each pair about 80 s quiet)")
    parser.add_argument("--workers-only", action="store_true",
                        help="only part 2, the 1-worker and 2-worker sweeps")
    args = parser.parse_args()
    separate = args.separate or args.load_cases
    commands = min(args.commands, args.load_cases)
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        load_before = os.getloadavg()
        shared = None if args.workers_only else \
            shared_model(folder, args.cells, args.load_cases, separate, commands)
        spreads = [workers(folder, args.independent, 10, args.repeats)]
        if args.large:
            spreads.append(workers(folder, args.large, 32, args.large_repeats))
        load_after = os.getloadavg()
    print(f"# Sweep benchmark ({os.cpu_count()} cores; load average "
          f"{load_before[0]:.1f} before, {load_after[0]:.1f} after)\n")
    if shared is not None:
        timed = "" if separate == args.load_cases else \
            f" ({separate} of them timed, their mean × {args.load_cases})"
        print(f"- {shared['cases']} load cases on one {args.cells}² model: sweep "
              f"{shared['sweep_s']:.1f} s ({shared['models']} model); separate runs in this "
              f"process {shared['separate_s']:.1f} s{timed}: ×{shared['ratio']:.1f}; separate "
              f"`splinedeform run` commands {shared['command_s']:.1f} s ({commands} of them "
              f"timed, their mean × {args.load_cases}): ×{shared['command_ratio']:.1f} "
              "(goal ≥ ×20)")
    for spread in spreads:
        goal = " (goal ≥ ×1.7)" if spread["cells"] == 10 else ""
        print(f"- {spread['cases']} independent {spread['cells']}² cases (medians of "
              f"{spread['runs']} alternations): 1 worker {spread['one_s']:.2f} s, 2 workers "
              f"{spread['two_s']:.2f} s: ×{spread['ratio']:.2f} the throughput{goal}; the "
              f"cases themselves on the busiest worker {spread['one_run_s']:.2f} s and "
              f"{spread['two_run_s']:.2f} s: ×{spread['run_ratio']:.2f}")


if __name__ == "__main__":
    main()
