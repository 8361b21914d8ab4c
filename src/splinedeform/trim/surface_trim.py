"""A trim region checked against the surface it trims."""

from __future__ import annotations

from typing import Any

import numpy as np

from ..errors import InputError
from .loops import Loop, TrimDomain


def loop_outside(surface: Any, loop: Loop) -> str | None:
    """What is wrong when ``loop`` does not lie strictly inside the parameter rectangle
    ``(0, L_u) × (0, L_v)`` of ``surface`` (a loop on the rectangle's edge would leave the
    knot cells); None when it does. A spline loop is bounded by its control points."""
    (_, lu), (_, lv) = surface.domain
    low, high = (np.asarray(b, dtype=float) for b in loop.bounds())
    if np.any(low <= 0.0) or high[0] >= lu or high[1] >= lv:
        return (f"reaches outside the parameter domain (0, {lu:g}) × (0, {lv:g}) of the "
                f"surface: it spans [{low[0]:g}, {high[0]:g}] × [{low[1]:g}, {high[1]:g}]")
    return None


def checked_trim(surface: Any, domain: Any) -> TrimDomain:
    """``domain`` if it is a :class:`TrimDomain` whose loops all lie inside the parameter
    rectangle of ``surface`` (:func:`loop_outside`)."""
    if not isinstance(domain, TrimDomain):
        raise InputError(f"a surface's trim must be a splinedeform.trim.TrimDomain, got "
                         f"{type(domain).__name__}")
    for k, loop in enumerate(domain.loops):
        problem = loop_outside(surface, loop)
        if problem:
            raise InputError(f"trim loop {'the outer loop' if k == 0 else f'hole {k}'} "
                             f"{problem}")
    return domain
