"""The cheapest setting of a numerical method that reaches the target accuracy.

Settings are levels ``k``: Radau IIA and generalised-α take ``round(√2^k)`` equal steps per
interval between frames (a factor √2 between levels), Newmark ``dt = t_end / (250·2^k)``,
the ``solve_ivp`` methods ``rtol = 10^-(2+k)`` with ``atol = rtol · max |p_ref - p_rest|``.
From a start level, a failing level jumps to the finer level its order predicts; a passing
level is followed by the next coarser one until that fails or no longer costs less.
"""

from __future__ import annotations

import math
from typing import Any, Protocol

from . import timing
from .cases import Case
from .timing import Attempt

NUMERICAL = ("radau7", "radau3", "genalpha", "newmark", "rk45", "dop853", "radau", "bdf")
SUBSTEP_METHODS = ("radau7", "radau3", "genalpha")
"""Methods whose setting is a number of equal steps per frame interval, ``round(√2^k)``."""
DEFAULT_METHODS = ("radau7", "radau3", "genalpha", "radau")
MAX_LEVEL = {"radau7": 20, "radau3": 24, "genalpha": 30, "newmark": 14, "rk45": 10,
             "dop853": 10, "radau": 10, "bdf": 10}
START_LEVEL = {"radau7": 0, "radau3": 2, "genalpha": 8, "newmark": 1, "rk45": 2, "dop853": 2,
               "radau": 2, "bdf": 2}
ORDER = {"radau7": 13, "radau3": 5, "genalpha": 2}


class Limits(Protocol):
    """What a search needs to know: the accuracy to reach and the seconds one run may take."""

    target: float
    budget: float


def substeps(level: int) -> int:
    """Steps per frame interval at a level: ``round(√2^k)`` (a factor √2 between levels)."""
    return max(1, round(math.sqrt(2.0) ** level))


def options(method: str, level: int, case: Case) -> dict[str, Any]:
    """Solver settings of a level (see the module docstring)."""
    if method in SUBSTEP_METHODS:
        return {"substeps": substeps(level)}
    if method == "newmark":
        return {"dt": case.t_end / (250 * 2**level)}
    rtol = 10.0 ** -(2 + level)
    return {"rtol": rtol, "atol": rtol * case.scale}


def setting_label(method: str, level: int) -> str:
    if method in SUBSTEP_METHODS:
        return f"{substeps(level)} steps/frame"
    if method == "newmark":
        return f"dt = t_end/{250 * 2**level}"
    return f"rtol = 1e-{2 + level:02d}"


def next_level(method: str, level: int, error: float, target: float) -> int:
    """Predicted finer level: order 2 for Newmark (error ∝ dt²), ``p`` for Radau IIA and
    gen-α (error ∝ h^p, a factor √2^p per level), error ∝ rtol otherwise."""
    ratio = error / target if math.isfinite(error) else 1e6
    per_level = 4.0 if method == "newmark" else 10.0
    if method in ORDER:
        per_level = math.sqrt(2.0) ** ORDER[method]
    jump = math.ceil(math.log(max(ratio, 1.0) * 1.2) / math.log(per_level))
    return level + min(max(jump, 1), 3)


def search(case: Case, method: str, start: int, limits: Limits, floor: int = -1
           ) -> tuple[dict[int, Attempt], int | None]:
    """Cheapest level reaching ``limits.target`` (each run stopped after ``limits.budget`` s).

    Levels at or below ``floor`` are known to miss the target (they missed it by more than
    ten times on a smaller net, and errors grow with the net) and are not tried.
    Returns all attempts and the cheapest passing level (``None`` if none passed).
    """
    tried: dict[int, Attempt] = {}
    level = start
    while 0 <= level <= MAX_LEVEL[method]:
        result = tried[level] = timing.attempt(case, method, level, limits.budget)
        if result.stopped:
            break
        if result.error <= limits.target:
            finer = tried.get(level + 1)
            not_cheaper = (finer is not None and finer.error <= limits.target
                           and result.seconds >= 0.9 * finer.seconds)
            if level == 0 or level - 1 in tried or level - 1 <= floor or not_cheaper:
                break
            level -= 1
        else:
            if level + 1 in tried:
                break
            level = next_level(method, level, result.error, limits.target)
    good = [lv for lv, a in tried.items() if a.error <= limits.target]
    return tried, (min(good, key=lambda lv: tried[lv].seconds) if good else None)
