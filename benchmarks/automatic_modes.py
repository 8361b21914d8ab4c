"""The analytic path with the number of modes chosen for an accuracy, on the bench plate.

    python benchmarks/automatic_modes.py 64          # cells per direction
    python benchmarks/automatic_modes.py 64 state    # only one state (or: frames)

For the ``clamped`` bench plate (200 frames over ten periods) and for one state at
``t = 0.37 t_end``: time from scratch (assembly included, as in the cost study) of
``dynamic(..., tolerance=tol, times=frames)`` for a few tolerances, and the max relative
error of its control points against the all-modes solution (the cost study's metric). BLAS
on one thread. Prints one line per setting; the all-modes time is printed too.
"""

from __future__ import annotations

import sys
import time

import numpy as np

from splinedeform import bench, bench_goals


def timed(cells: int, times: np.ndarray, **options: float) -> tuple[float, np.ndarray, dict]:
    start = time.perf_counter()
    model = bench.build_model("clamped", cells)
    t_end = bench.reference_t_end("clamped")
    sol = model.dynamic(bench.study_load(t_end), t_end, times=times, **options)
    nets = sol.control_points(times)
    return time.perf_counter() - start, nets, getattr(sol, "truncation", {})


def main(cells: int, which: str = "both") -> None:
    t_end = bench.reference_t_end("clamped")
    cases = {"frames": ("200 frames", np.linspace(0.0, t_end, 200)),
             "state": ("one state", np.array([0.37 * t_end]))}
    with bench_goals.blas_threads(1) as threads:
        print(threads, flush=True)
        for label, times in (cases.values() if which == "both" else [cases[which]]):
            full_s, full, _ = timed(cells, times)
            rest = bench.build_model("clamped", cells).surface.control_points
            scale = np.abs(full - rest).max()
            print(f"{cells}² {label}: all modes {full_s:.3g} s", flush=True)
            for tol in (1e-6, 1e-7):
                s, nets, report = timed(cells, times, tolerance=tol)
                err = np.abs(nets - full).max() / scale
                print(f"    tolerance {tol:g}: {s:.3g} s, {report.get('modes')} modes, "
                      f"bound {report.get('bound', float('nan')):.2g}, max error {err:.2e}",
                      flush=True)


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 64,
         sys.argv[2] if len(sys.argv) > 2 else "both")
