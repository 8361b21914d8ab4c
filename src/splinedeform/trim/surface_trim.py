"""A trim region checked against the surface it trims."""

from __future__ import annotations

from typing import Any

import numpy as np

from ..errors import InputError
from .loops import TrimDomain


def checked_trim(surface: Any, domain: Any) -> TrimDomain:
    """``domain`` if it is a :class:`TrimDomain` whose loops lie inside the parameter
    rectangle ``[0, L_u] × [0, L_v]`` of ``surface`` (a loop touching the rectangle's edge
    is refused: its cells would leave the grid)."""
    if not isinstance(domain, TrimDomain):
        raise InputError(f"a surface's trim must be a splinedeform.trim.TrimDomain, got "
                         f"{type(domain).__name__}")
    (_, lu), (_, lv) = surface.domain
    for k, loop in enumerate(domain.loops):
        low, high = (np.asarray(b, dtype=float) for b in loop.bounds())
        if np.any(low <= 0.0) or high[0] >= lu or high[1] >= lv:
            name = "the outer loop" if k == 0 else f"hole {k}"
            raise InputError(f"trim loop {name} reaches outside the parameter domain "
                             f"(0, {lu:g}) × (0, {lv:g}): it spans [{low[0]:g}, {high[0]:g}] × "
                             f"[{low[1]:g}, {high[1]:g}]")
    return domain
