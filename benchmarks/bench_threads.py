"""BLAS threads of the library's calls: one (the default) against BLAS's own setting.

    python benchmarks/bench_threads.py            # 32² and 64², quiet and with a busy process
    python benchmarks/bench_threads.py --sizes 32 --repeats 1

Each run is the README's call on the cost study's clamped plate (``Model.dynamic(load,
t_end)``, then ``control_points`` at 201 frames, assembly included) in a fresh process with
``SPLINEDEFORM_THREADS=1`` or ``SPLINEDEFORM_THREADS=blas`` (BLAS's own thread count), once
on the machine as it is and once beside one extra busy process
(``python -c 'while True: pass'``). Prints a markdown table with the 1-minute load average
at the start of each run.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import time

RUN = """
import time
from splinedeform.bench.cases import make_case
start = time.perf_counter()
case = make_case("clamped", {cells}, 201)
solution = case.fresh_model().dynamic(case.load, case.t_end)
solution.control_points(case.times)
print(time.perf_counter() - start, solution.basis.size)
"""


def one_run(cells: int, threads: str) -> tuple[float, int]:
    """Seconds and modes of one default call in a fresh process."""
    env = dict(os.environ, SPLINEDEFORM_THREADS=threads)
    out = subprocess.run([sys.executable, "-c", RUN.format(cells=cells)], env=env,
                         capture_output=True, text=True, check=True).stdout.split()
    return float(out[0]), int(out[1])


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__,
                                formatter_class=argparse.RawTextHelpFormatter)
    p.add_argument("--sizes", default="32,64", help="cells per direction, comma-separated")
    p.add_argument("--repeats", type=int, default=2, help="runs per setting (the fastest kept)")
    args = p.parse_args(argv)
    sizes = [int(s) for s in args.sizes.split(",")]
    print("| net | machine | load average | 1 thread (default) | BLAS's own threads | ratio |")
    print("|---|---|---|---|---|---|")
    for busy in (False, True):
        spinner = (subprocess.Popen([sys.executable, "-c", "while True: pass"])
                   if busy else None)
        try:
            if spinner is not None:
                time.sleep(2.0)
            for cells in sizes:
                load = os.getloadavg()[0]
                one = min(one_run(cells, "1") for _ in range(args.repeats))
                own = min(one_run(cells, "blas") for _ in range(args.repeats))
                print(f"| {cells}² ({one[1]} modes) | {'+1 busy process' if busy else 'as is'} "
                      f"| {load:.2f} | {one[0]:.2f} s | {own[0]:.2f} s | "
                      f"×{own[0] / one[0]:.2f} |", flush=True)
        finally:
            if spinner is not None:
                spinner.kill()
                spinner.wait()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
