"""Step placement shared by the one-step integrators: stops, substeps, moving coordinates."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

Array = NDArray[np.float64]


def left_limit(a: float, b: float) -> float:
    """A time just before ``b`` inside ``[a, b]``: the force's left limit at a jump at ``b``."""
    return b - 1e-12 * (b - a)


def check_step(dt: float | None, substeps: int | None) -> None:
    """Reject a non-positive or non-finite step and a substep count below one."""
    if dt is not None and substeps is not None:
        raise ValueError("give either dt= or substeps=, not both")
    if dt is not None and (not np.isfinite(float(dt)) or float(dt) <= 0):
        raise ValueError(f"step dt must be finite and > 0, got {dt}")
    if substeps is not None and (int(substeps) != substeps or int(substeps) < 1):
        raise ValueError(f"substeps must be an integer >= 1, got {substeps}")


def stops_and_substeps(breakpoints: list[float], t_end: float, out_times: Array,
                       dt: float | None, substeps: int | None) -> tuple[Array, Array]:
    """Stops (``0``, output times, breakpoints inside ``(0, t_end)``, ``t_end``, near-equal
    ones merged) and the number of equal steps in each interval between them.

    ``substeps`` steps per interval, or ``ceil(length / dt)``; default one step per interval.
    """
    check_step(dt, substeps)
    inner = [b for b in breakpoints if 0.0 < b < t_end]
    stops = np.union1d(np.union1d(out_times, inner), [0.0, t_end])
    stops = stops[np.concatenate([[True], np.diff(stops) > 1e-9 * t_end])]
    lengths = np.diff(stops)
    if substeps is not None:
        counts = np.full(lengths.size, int(substeps))
    elif dt is not None:
        counts = np.maximum(1, np.ceil(lengths / float(dt) - 1e-9).astype(int))
    else:
        counts = np.ones(lengths.size, dtype=int)
    return stops, counts


def active_columns(force: Callable[[float], Array], breakpoints: list[float], t_end: float,
                   d0: Array, v0: Array, probes: int = 13) -> Array:
    """Columns (coordinates) that move: non-zero initial state, or non-zero force at
    ``probes`` irrational fractions of each interval between breakpoints."""
    moving = np.any(d0 != 0, axis=0) | np.any(v0 != 0, axis=0)
    cuts = sorted({0.0, t_end, *[b for b in breakpoints if 0.0 < b < t_end]})
    frac = np.modf(np.arange(1, probes + 1) * (np.sqrt(5.0) - 1) / 2)[0]
    for a, b in zip(cuts[:-1], cuts[1:]):
        for f in frac:
            moving |= np.any(np.asarray(force(a + f * (b - a))) != 0, axis=0)
    return np.flatnonzero(moving)
