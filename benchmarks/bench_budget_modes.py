"""The budget's work estimate of a modes solve against the processor time of the run.

A pinned drum of 4² cells, 3 modes, written with its per-mode files (mode fields, each
mode's nets, each animated mode's GIF). For each case the estimate in seconds
(``estimate(...).total("work") / 1e9``, :data:`splinedeform.budget.OPS_PER_SECOND`) and
the processor time of ``run`` (``time.process_time``: this process only, less sensitive to
a busy machine than the wall clock, which is printed too), measured in one run.

Run ``python benchmarks/bench_budget_modes.py``; report the load average beside it.
"""

from __future__ import annotations

import os
import tempfile
import time

DRUM = """\
[surface]
shape = "plane"
cells = 4

[material]
w10 = 1.0
w01 = 1.0

[boundary]
u0 = "pinned"
u1 = "pinned"
v0 = "pinned"
v1 = "pinned"

[solve]
kind = "modes"
modes = 3
frames = {frames}

[output]
formats = {formats}
resolution = 6
animate_modes = {animated}
"""

CASES = [('["vtu", "json", "npz", "gif"]', "[1, 2, 3]", 20),
         ('["gif"]', "[1, 2, 3]", 40),
         ('["vtu", "json", "npz"]', "[1]", 20)]


def main() -> None:
    from splinedeform.budget import OPS_PER_SECOND, estimate
    from splinedeform.pipeline import run
    from splinedeform.scenario import build, parse_scenario

    print(f"load average {os.getloadavg()[0]:.2f} (1 min)")
    print("| formats | animated | frames | estimate (s) | processor (s) | wall (s) | ratio |")
    print("|---|---|---|---|---|---|---|")
    for formats, animated, frames in CASES:
        s = parse_scenario(DRUM.format(formats=formats, animated=animated, frames=frames),
                           source="drum.toml")
        guess = estimate(s, build(s).model).total("work") / OPS_PER_SECOND
        with tempfile.TemporaryDirectory() as folder:
            cpu, wall = time.process_time(), time.perf_counter()
            run(s, folder)
            cpu, wall = time.process_time() - cpu, time.perf_counter() - wall
        print(f"| {formats} | {animated} | {frames} | {guess:.3g} | {cpu:.3g} | {wall:.3g} "
              f"| {guess / cpu:.3g} |")
    print(f"load average {os.getloadavg()[0]:.2f} (1 min)")


if __name__ == "__main__":
    main()
