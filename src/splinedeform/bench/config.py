"""Settings of the cost study, their defaults and their checks."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from ..budget import Budget, net_memory, show
from ..errors import InputError
from .cases import FAMILIES
from .search import DEFAULT_METHODS, NUMERICAL


YARDSTICK_CELLS = 16
"""Largest net (cells per direction) on which the all-modes solution is checked against
DOP853 at ``rtol = 1e-12``: the default study's two smallest nets, 8² and 16²."""


@dataclass(frozen=True)
class Study:
    """Settings of the cost study.

    Parameters
    ----------
    sizes : cells per direction of the nets (square nets ``m × m``).
    frames : number of output frames ``F``.
    target : accuracy every method must reach (max relative error at the frames).
    budget : seconds allowed to one numerical run before it is stopped and extrapolated.
    methods : numerical methods compared with the analytic solution.
    families : problem families (``clamped``, ``region``).
    yardstick_sizes : the all-modes solution is checked against DOP853 (``rtol = 1e-12``)
        on this many of the smallest sizes, those of at most :data:`YARDSTICK_CELLS` cells
        per direction only (an explicit stiff integrator at that tolerance takes longer than
        any budget beyond: at 32² it had not finished after 480 s).
    region_max : largest net of the ``region`` family (its sweep stops there).
    large_budget : budget of one run on nets above 64×64 (where one Radau IIA-7 run
        takes longer than ``budget``).
    goals : also measure the goals of the analytic path at scale (separate processes).
    regimes : also the regimes b–e (horizon, load cases, one state, probes).
    """

    sizes: tuple[int, ...] = (8, 16, 32, 64, 128)
    frames: int = 200
    target: float = 1e-6
    budget: float = 30.0
    methods: tuple[str, ...] = DEFAULT_METHODS
    families: tuple[str, ...] = FAMILIES
    yardstick_sizes: int = 2
    region_max: int = 64
    large_budget: float = 300.0
    goals: bool = False
    regimes: bool = True

    def budget_for(self, cells: int) -> float:
        return self.large_budget if cells > 64 else self.budget


QUICK = Study(sizes=(3, 4), frames=20, target=1e-3, budget=5.0, large_budget=5.0,
              methods=("radau7", "radau3", "genalpha"), yardstick_sizes=1, goals=False,
              regimes=False)
"""The smoke run (``splinedeform bench --quick``): the two smallest nets (3×3 and 4×4 cells),
20 frames, a loose target (1e-3) so that every method needs few steps, regime a only, the
integrators that take the mass matrix (scipy's Radau left to the full study), the all-modes
solution checked against DOP853 on the smallest net only.

Most of a quick run on the 4×4 and 6×6 nets at 1e-4 went to generalised-α (512 steps per
frame), scipy's Radau and the DOP853 checks; docs/cost.md gives the measured time.
"""


def _sizes(sizes: Sequence[Any]) -> tuple[int, ...]:
    sizes = tuple(sizes)
    if not sizes or any(isinstance(s, bool) or not isinstance(s, (int, np.integer)) or s < 2
                        for s in sizes):
        raise InputError(f"sizes must be integers >= 2 (cells per direction), got {list(sizes)}")
    limit = Budget().memory
    too_large = [int(s) for s in sizes if net_memory(int(s), int(s)) > limit]
    if too_large:
        largest = max(too_large)
        raise InputError(f"sizes {too_large}: a {largest} x {largest}-cell net needs about "
                         f"{show('memory', net_memory(largest, largest))} for its control "
                         f"points and matrices alone, more than the {show('memory', limit)} "
                         "a run may take; choose smaller sizes (the default study goes to 128)")
    return tuple(sorted({int(s) for s in sizes}))


def make_study(sizes: Sequence[int] | None = None, quick: bool = False,
               frames: int | None = None, target: float | None = None,
               budget: float | None = None, methods: Sequence[str] | None = None,
               families: Sequence[str] | None = None, goals: bool | None = None,
               regimes: bool | None = None) -> Study:
    """The default (or quick) study with the given settings changed, each checked."""
    study = QUICK if quick else Study()
    changes: dict[str, Any] = {}
    if sizes is not None:
        changes["sizes"] = _sizes(sizes)
    if frames is not None:
        if int(frames) < 2:
            raise InputError(f"frames must be >= 2, got {frames}")
        changes["frames"] = int(frames)
    if target is not None:
        if not 0 < float(target) < 1:
            raise InputError(f"target must be in (0, 1), got {target}")
        changes["target"] = float(target)
    if budget is not None:
        if not float(budget) > 0:
            raise InputError(f"budget must be > 0 seconds, got {budget}")
        changes["budget"] = float(budget)
        changes["large_budget"] = max(float(budget), study.large_budget if not quick else 0.0)
    if methods is not None:
        bad = [m for m in methods if m not in NUMERICAL]
        if bad:
            raise InputError(f"unknown numerical method(s) {bad}; choose from {NUMERICAL}")
        changes["methods"] = tuple(methods)
    if families is not None:
        bad = [f for f in families if f not in FAMILIES]
        if bad:
            raise InputError(f"unknown problem family(ies) {bad}; choose from {FAMILIES}")
        changes["families"] = tuple(families)
    if goals is not None:
        changes["goals"] = bool(goals)
    if regimes is not None:
        changes["regimes"] = bool(regimes)
    return replace(study, **changes)


def from_record(record: dict[str, Any]) -> Study:
    """The study of a ``bench.json`` record (lists back to tuples; unknown keys dropped)."""
    known = Study.__dataclass_fields__
    return Study(**{k: tuple(v) if isinstance(v, list) else v
                    for k, v in record.items() if k in known})
