"""Cost of evaluating a spline surface: ours against scipy, as a user calls it.

A cubic net of 64 × 64 cells (open knots, 67 × 67 control points) is evaluated

* on parameter grids of 20 × 20, 200 × 200 and 1000 × 1000 (:data:`GRID_SAMPLES`):
  ``Surface.evaluate_grid`` against the same products ``B_u P B_vᵀ`` with the collocation
  matrices of ``scipy.interpolate.BSpline.design_matrix``;
* at the 40 000 flattened grid points and at 1 000 random points: ``Surface.evaluate``
  against ``scipy.interpolate.NdBSpline`` on the same points (and ``∂x/∂u`` by
  ``Surface.derivative(u, v, 1, 0)`` against ``NdBSpline(..., nu=(1, 0))``);
* at one point given as two Python floats, ``surface.evaluate(u, v)`` as the README calls
  it, against ``NdBSpline`` called on that point;
* the first call of ``evaluate`` on a new surface against constructing an ``NdBSpline`` and
  calling it, for one point (the README's ``sol.surface(t).evaluate(u, v)``: no patches
  are built) and for the 40 000 points (which build the surface's Bézier patches).

All must agree with scipy to 1e-12 (relative to the largest coordinate). Times are the
best of several repeats, ours and scipy's taken in turn in the same run (so that a load
from other work hits both alike), and ``ratio = reference / ours`` (above 1: ours is
faster). A pointwise evaluation is not compared with the grid products: on a grid the
tensor structure saves a factor ``(n+1)`` per point that scattered points cannot have.

Run ``python benchmarks/bench_evaluate.py [--quick]``; ``run(quick)`` returns the rows
for the benchmark table.
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Callable
from typing import Any

import numpy as np
from scipy.interpolate import BSpline, NdBSpline

from splinedeform.basis import BSplineBasis
from splinedeform.surface import Surface

CELLS = 64
DEGREE = 3
SAMPLES = 200
GRID_SAMPLES = (20, 200, 1000)
TOLERANCE = 1e-12


def best_times(ours: Callable[[], Any], reference: Callable[[], Any], repeats: int
               ) -> tuple[float, Any, float, Any]:
    """Smallest wall times of ``repeats`` calls of each, taken in turn, and the last results."""
    best_ours = best_reference = np.inf
    mine = theirs = None
    for _ in range(repeats):
        start = time.perf_counter()
        theirs = reference()
        best_reference = min(best_reference, time.perf_counter() - start)
        start = time.perf_counter()
        mine = ours()
        best_ours = min(best_ours, time.perf_counter() - start)
    return best_ours, mine, best_reference, theirs


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


def reference_spline(surface: Surface) -> NdBSpline:
    """The surface as a scipy ``NdBSpline`` (the same knots, degrees and control net)."""
    bu, bv = surface.basis_u, surface.basis_v
    return NdBSpline((bu.knots, bv.knots), surface.control_points, (bu.degree, bv.degree))


def run(quick: bool = False) -> list[dict]:
    """Time the evaluations; rows ``name, ours_s, reference_s, ratio``.

    Raises ``AssertionError`` if any evaluation differs from scipy's by more than 1e-12
    (relative to the largest coordinate).
    """
    repeats = 5 if quick else 15
    surface = make_surface()
    spline = reference_spline(surface)
    u = v = np.linspace(0.0, 1.0, SAMPLES)
    U, V = np.meshgrid(u, v, indexing="ij")
    grid_points = np.stack([U.ravel(), V.ravel()], axis=-1)
    scattered = np.random.default_rng(1).random((1000, 2))
    su, sv = scattered[:, 0].copy(), scattered[:, 1].copy()
    label = f"{CELLS}x{CELLS}-cell cubic"
    cases: list[tuple[str, Callable[[], Any], Callable[[], Any], int]] = [
        (f"evaluate_grid ({n}x{n} samples, {label}) vs design_matrix products",
         lambda x=x: surface.evaluate_grid(x, x), lambda x=x: reference_grid(surface, x, x),
         max(repeats, repeats * SAMPLES // n))
        for n, x in ((n, np.linspace(0.0, 1.0, n)) for n in GRID_SAMPLES)]
    cases += [
        (f"evaluate pointwise ({SAMPLES * SAMPLES} grid points, {label}) vs NdBSpline",
         lambda: surface.evaluate(U, V).reshape(-1, 3), lambda: spline(grid_points), repeats),
        (f"evaluate pointwise (1000 random points, {label}) vs NdBSpline",
         lambda: surface.evaluate(su, sv), lambda: spline(scattered), 5 * repeats),
        (f"derivative du=1 pointwise ({SAMPLES * SAMPLES} grid points) vs NdBSpline nu=(1,0)",
         lambda: surface.derivative(U, V, 1, 0).reshape(-1, 3),
         lambda: spline(grid_points, nu=(1, 0)), repeats),
        (f"evaluate one point (two floats, {label}) vs NdBSpline",
         lambda: surface.evaluate(0.3, 0.7), lambda: spline([0.3, 0.7]), 200 * repeats),
        ("one point on a new surface (sol.surface(t).evaluate(u, v)) vs NdBSpline built and "
         "called",
         lambda: surface.with_control_points(surface.control_points).evaluate(0.3, 0.7),
         lambda: reference_spline(surface)([0.3, 0.7]), 20 * repeats),
        (f"first evaluate on a new surface ({SAMPLES * SAMPLES} points) vs NdBSpline built "
         "and called",
         lambda: surface.with_control_points(surface.control_points).evaluate(U, V).reshape(-1, 3),
         lambda: reference_spline(surface)(grid_points), repeats),
    ]
    rows = []
    for name, ours, reference, count in cases:
        ours_s, mine, reference_s, theirs = best_times(ours, reference, count)
        theirs = np.asarray(theirs)
        error = float(np.abs(np.asarray(mine) - theirs).max()) / float(np.abs(theirs).max())
        assert error < TOLERANCE, f"{name}: differs from scipy by {error:.2e}"
        rows.append({"name": name, "ours_s": ours_s, "reference_s": reference_s,
                     "ratio": reference_s / ours_s})
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer repeats")
    rows = run(parser.parse_args().quick)
    print(f"{'benchmark':<92} {'ours [s]':>10} {'scipy [s]':>10} {'scipy/ours':>11}")
    for row in rows:
        print(f"{row['name']:<92} {row['ours_s']:>10.3g} {row['reference_s']:>10.3g} "
              f"{row['ratio']:>11.2f}")
    print(f"all agree with the scipy reference to {TOLERANCE:g}")


if __name__ == "__main__":
    main()
