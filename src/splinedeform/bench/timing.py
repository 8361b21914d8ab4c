"""Timing one run: the BLAS thread setting, a budget that stops a run, the machine.

A numerical run is timed through the public API (``Model.dynamic(load, t_end, method=…)``)
with its load's time profiles wrapped in :class:`Deadline`: the integrators ask for the load
as they step, so a profile that raises :class:`OverBudget` after a deadline stops a run
where it is, and the time it was last asked for says how far the stepping got.
"""

from __future__ import annotations

import contextlib
import math
import os
import platform
import time
from collections.abc import Iterator
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import loads
from ..errors import InputError
from .cases import Case, relative_error

Array = NDArray[np.float64]


@contextlib.contextmanager
def blas_threads(n: int | None = None) -> Iterator[str]:
    """Limit BLAS/OpenMP threads to ``n`` (threadpoolctl); yields the setting as text.

    ``None`` (the study's default) pins nothing: the library runs as it ships, its own calls
    with the BLAS threads of :mod:`splinedeform.threads`.
    """
    if n is None:
        from ..threads import threads
        yield (f"BLAS threads not pinned by the study; the library's own setting in its "
               f"calls: {threads()} (splinedeform.threads, SPLINEDEFORM_THREADS)")
        return
    try:
        from threadpoolctl import threadpool_limits
    except ImportError:                                         # pragma: no cover
        yield "BLAS threads not controlled (threadpoolctl missing)"
        return
    with threadpool_limits(limits=n):
        yield f"BLAS threads limited to {n} (threadpoolctl)"


class OverBudget(Exception):
    """Raised inside a numerical run when its time is up."""


class Deadline(loads.Profile):
    """A load profile that raises :class:`OverBudget` once ``clock() > deadline``.

    ``reached`` is the time of the *latest* call, not the largest: before stepping, the
    integrators probe the load at times spread over ``[0, t_end]`` (up to 97 % of it) to find
    the coordinates that move; the stepping itself asks in increasing time, so the latest
    call is where a stopped run was.
    """

    def __init__(self, inner: loads.Profile, deadline: float):
        self.inner = inner
        self.deadline = deadline
        self.reached = 0.0

    def __call__(self, t: ArrayLike) -> Array:
        if time.perf_counter() > self.deadline:
            raise OverBudget
        self.reached = float(np.max(t))
        return self.inner(t)

    def jumps(self) -> list[tuple[float, float]] | None:
        return self.inner.jumps()

    def breakpoints(self) -> list[float]:
        return self.inner.breakpoints()


def timed_load(load: loads.Load, deadline: float) -> tuple[loads.Load, list[Deadline]]:
    """``load`` with every term's profile wrapped in a :class:`Deadline`."""
    terms, clocks = [], []
    for term in load.terms():
        clock = Deadline(term.profile, deadline)
        terms.append(replace(term, profile=clock))
        clocks.append(clock)
    out = terms[0]
    for term in terms[1:]:
        out = out + term
    return out, clocks


@dataclass
class Attempt:
    """One numerical run at one setting level."""

    level: int
    seconds: float
    error: float = math.inf
    stopped: bool = False
    estimate: float = math.nan
    progress: float = math.nan


def attempt(case: Case, method: str, level: int, budget: float,
            opts: dict[str, Any] | None = None) -> Attempt:
    """Run ``method`` once at ``level`` (or explicit ``opts``); stop it after ``budget`` s.

    The time excludes the assembly (the case's model is built); the error is measured
    against ``case.reference`` at ``case.times``. A stopped run's full cost is extrapolated
    linearly from the simulated time reached (``estimate``).
    """
    from .search import options

    start = time.perf_counter()
    load, clocks = timed_load(case.load, start + budget)
    try:
        sol = case.model.dynamic(load, case.t_end, method=method, times=case.times,
                                 **(opts or options(method, level, case)))
        nets = sol.control_points(case.times)
    except OverBudget:
        elapsed = time.perf_counter() - start
        reached = min(c.reached for c in clocks)
        estimate = elapsed * case.t_end / max(reached, 1e-3 * case.t_end)
        return Attempt(level, elapsed, stopped=True, estimate=estimate,
                       progress=reached / case.t_end)
    except InputError:                      # the integrator gave up: treat as inaccurate
        return Attempt(level, time.perf_counter() - start)
    return Attempt(level, time.perf_counter() - start, relative_error(nets, case))


def assembly_seconds(case: Case, repeats: int = 3) -> float:
    """Median time to build (assemble) the case's model afresh."""
    runs = []
    for _ in range(repeats):
        start = time.perf_counter()
        case.fresh_model()
        runs.append(time.perf_counter() - start)
    return sorted(runs)[len(runs) // 2]


def median_run(run: Any, repeats: int = 3, long: float = 3.0) -> tuple[float, Any]:
    """Time ``run()`` up to ``repeats`` times (once when a run takes over ``long`` s).

    Returns the median time and the result of the first run.
    """
    times, first = [], None
    for i in range(max(1, repeats)):
        start = time.perf_counter()
        result = run()
        times.append(time.perf_counter() - start)
        if i == 0:
            first = result
        if times[-1] > long:
            break
    return sorted(times)[len(times) // 2], first


def machine() -> str:
    """CPU model, cores, memory and library versions."""
    import scipy

    cpu = platform.processor() or platform.machine()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
        mem = next(line for line in Path("/proc/meminfo").read_text().splitlines()
                   if line.startswith("MemTotal"))
        memory = f", {int(mem.split()[1]) / 2**20:.0f} GiB RAM"
    except (OSError, StopIteration, ValueError):
        memory = ""
    return (f"{cpu}, {os.cpu_count()} cores{memory}; Python {platform.python_version()}, "
            f"numpy {np.__version__}, scipy {scipy.__version__}")


def load_average() -> str:
    """The 1-minute load average of the machine when asked (``os.getloadavg``)."""
    try:
        return f"{os.getloadavg()[0]:.2f}"
    except OSError:                                             # pragma: no cover
        return "unknown"
