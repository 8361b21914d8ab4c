"""What the coupled Kirchhoff–Love shell costs next to the scalar plate models.

The Scordelis–Lo roof (radius 25, length 50, 80° arc, cubic splines) on ``m × m`` cells,
solved three ways: ``parametric`` and ``intrinsic`` (thin plate under tension, curved ends
pinned, one matrix shared by x, y and z) and ``shell`` (Kirchhoff–Love, rigid diaphragms
at the curved ends, x, y and z coupled in ``3n`` unknowns). For each: the number of
unknowns, the assembly, one static solve, the lowest 10 modes (sparse Lanczos) and the
complete analytic dynamic solution (every mode by dense ``eigh``) read at 200 frames.
Times are single calls in one run (BLAS on one thread when threadpoolctl is present).

Run ``python benchmarks/bench_shell.py [--cells 8 16 24]``; it prints a markdown table.
"""

from __future__ import annotations

import argparse
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


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cells", type=int, nargs="+", default=[8, 16, 24])
    args = parser.parse_args()
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
