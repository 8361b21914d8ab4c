"""Cost of evaluating a spline surface on a grid: ours against a scipy reference.

A cubic net of 64 × 64 cells (open knots, 67 × 67 control points) is evaluated on a
200 × 200 parameter grid three ways:

* ``Surface.evaluate_grid`` — two sparse 1-D collocation matrices ``B_u``, ``B_v`` and
  the products ``B_u P B_vᵀ``;
* ``Surface.evaluate`` pointwise on the 40 000 flattened parameter pairs (one sparse
  row of ``n+1 × n+1`` products per point);
* the reference: ``scipy.interpolate.BSpline.design_matrix`` in both directions, then the
  same two products.

All three must agree to 1e-12. Times are the best of several repeats measured in the same
run, and ``ratio = reference / ours`` (above 1: ours is faster).

Run ``python benchmarks/bench_evaluate.py [--quick]``; ``run(quick)`` returns the rows
for the benchmark table.
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Callable
from typing import Any

import numpy as np
from scipy.interpolate import BSpline

from splinedeform.basis import BSplineBasis
from splinedeform.surface import Surface

CELLS = 64
DEGREE = 3
SAMPLES = 200
TOLERANCE = 1e-12


def best_time(call: Callable[[], Any], repeats: int) -> tuple[float, Any]:
    """Smallest wall time of ``repeats`` calls, and the last result."""
    best, result = np.inf, None
    for _ in range(repeats):
        start = time.perf_counter()
        result = call()
        best = min(best, time.perf_counter() - start)
    return best, result


def reference_grid(surface: Surface, u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """``B_u P B_vᵀ`` with the collocation matrices from ``BSpline.design_matrix``."""
    bu, bv = surface.basis_u, surface.basis_v
    Bu = BSpline.design_matrix(u, bu.knots, bu.degree)
    Bv = BSpline.design_matrix(v, bv.knots, bv.degree)
    P = surface.control_points
    n_u, n_v = surface.shape
    tmp = (Bu @ P.reshape(n_u, -1)).reshape(u.size, n_v, 3)
    out = Bv @ tmp.transpose(1, 0, 2).reshape(n_v, -1)
    return np.asarray(out).reshape(v.size, u.size, 3).transpose(1, 0, 2)


def make_surface(cells: int = CELLS, degree: int = DEGREE, seed: int = 0) -> Surface:
    """A random control net on open cubic bases over the unit square."""
    basis = BSplineBasis(degree, cells, 1.0, "open")
    P = np.random.default_rng(seed).normal(size=(basis.size, basis.size, 3))
    return Surface(P, basis, basis, name="random")


def run(quick: bool = False) -> list[dict]:
    """Time the three evaluations; rows ``name, ours_s, reference_s, ratio``.

    Raises ``AssertionError`` if any evaluation differs from the reference by more than
    1e-12 (relative to the largest coordinate).
    """
    repeats = 3 if quick else 7
    surface = make_surface()
    u = v = np.linspace(0.0, 1.0, SAMPLES)
    U, V = np.meshgrid(u, v, indexing="ij")
    reference_s, reference = best_time(lambda: reference_grid(surface, u, v), repeats)
    grid_s, grid = best_time(lambda: surface.evaluate_grid(u, v), repeats)
    point_s, points = best_time(lambda: surface.evaluate(U, V), max(1, repeats // 2))
    scale = float(np.abs(reference).max())
    for name, value in (("evaluate_grid", grid), ("evaluate", points)):
        error = float(np.abs(value - reference).max()) / scale
        assert error < TOLERANCE, f"{name} differs from the scipy reference by {error:.2e}"
    label = f"{SAMPLES}x{SAMPLES} samples, {CELLS}x{CELLS}-cell cubic"
    return [
        {"name": f"evaluate_grid ({label})", "ours_s": grid_s, "reference_s": reference_s,
         "ratio": reference_s / grid_s},
        {"name": f"evaluate pointwise ({label})", "ours_s": point_s,
         "reference_s": reference_s, "ratio": reference_s / point_s},
    ]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer repeats")
    rows = run(parser.parse_args().quick)
    print(f"{'benchmark':<58} {'ours [s]':>10} {'scipy [s]':>10} {'scipy/ours':>11}")
    for row in rows:
        print(f"{row['name']:<58} {row['ours_s']:>10.4f} {row['reference_s']:>10.4f} "
              f"{row['ratio']:>11.2f}")
    print(f"all agree with the scipy reference to {TOLERANCE:g}")


if __name__ == "__main__":
    main()
