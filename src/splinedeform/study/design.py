"""The design: the axes' values combined into cases.

- ``grid``: every combination (the Cartesian product) of the axes' values, the first axis
  varying slowest; a ``range`` gives ``count`` values ``a + (b - a) i/(count - 1)``
  (linear) or ``a (b/a)^(i/(count - 1))`` (log).
- ``random``: ``n`` points, each axis drawn independently: a ``range`` uniformly in
  ``[a, b]`` (log: ``log x`` uniform in ``[log a, log b]``), ``values`` one of them with
  equal chances (Monte Carlo).
- ``latin-hypercube``: ``n`` points whose projection on each axis puts one point in each
  of ``n`` equally likely strata (McKay, Beckman & Conover 1979), mapped like ``random``.
"""

from __future__ import annotations

import itertools
import math
from typing import Any

import numpy as np

from ..errors import InputError
from .read import AxisSpec, Sweep
from .schema import MAX_CASES


def axis_values(axis: AxisSpec) -> list[Any]:
    """The values of one grid axis (its ``values``, or ``count`` points of its ``range``)."""
    if axis.values is not None:
        return [_thawed(v) for v in axis.values]
    assert axis.range is not None and axis.count is not None
    return [_rounded(axis, x) for x in _spaced(axis, np.linspace(0.0, 1.0, axis.count))]


def _spaced(axis: AxisSpec, s: np.ndarray) -> np.ndarray:
    """``s ∈ [0, 1]`` mapped onto the range, linearly or in the logarithm."""
    assert axis.range is not None
    a, b = axis.range
    if axis.scale == "log":
        return np.exp(math.log(a) + s * (math.log(b) - math.log(a)))
    return a + s * (b - a)


def _rounded(axis: AxisSpec, x: float) -> Any:
    return int(round(float(x))) if axis.integer else float(x)


def _thawed(value: Any) -> Any:
    """A checked value back as TOML would give it (tuples → lists)."""
    return [_thawed(v) for v in value] if isinstance(value, tuple) else value


def design_points(sweep: Sweep) -> list[dict[str, Any]]:
    """The cases of the design: one ``{axis key: value}`` per case, in a fixed order.

    Raises
    ------
    InputError
        When a grid would hold more than :data:`~.schema.MAX_CASES` cases.
    """
    axes = sweep.axes
    if sweep.design == "grid":
        grids = [axis_values(axis) for axis in axes]
        total = math.prod(len(g) for g in grids)
        if total > MAX_CASES:
            raise InputError(f"{sweep.source}: the grid has {total} cases "
                             f"({' × '.join(str(len(g)) for g in grids)}); at most {MAX_CASES}")
        return [dict(zip((a.key for a in axes), point)) for point in itertools.product(*grids)]
    assert sweep.n is not None
    rng = np.random.default_rng(sweep.seed)
    if sweep.design == "random":
        unit = rng.random((sweep.n, len(axes)))
    else:
        from scipy.stats import qmc

        unit = qmc.LatinHypercube(d=len(axes), seed=rng).random(sweep.n)
    points = []
    for row in unit:
        point = {}
        for axis, s in zip(axes, row):
            if axis.values is not None:     # stratum i of len(values) equal ones
                point[axis.key] = _thawed(axis.values[min(int(s * len(axis.values)),
                                                          len(axis.values) - 1)])
            else:
                point[axis.key] = _rounded(axis, float(_spaced(axis, np.asarray(s))))
        points.append(point)
    return points
