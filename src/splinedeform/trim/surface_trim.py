"""A trim region checked against the surface it trims."""

from __future__ import annotations

from typing import Any

import numpy as np

from ..basis import BSplineBasis
from ..errors import InputError
from .cells import Grid
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


def trim_grid(surface: Any) -> Grid:
    """The knot cells of a surface that can be trimmed: equal cells in both directions
    (``uniform`` or ``open`` knots), one degree."""
    bases = (surface.basis_u, surface.basis_v)
    for name, basis in zip("uv", bases):
        if not isinstance(basis, BSplineBasis) or basis.kind not in ("uniform", "open"):
            kind = getattr(basis, "kind", type(basis).__name__)
            raise InputError(f"a trimmed surface needs equal knot cells ('uniform' or 'open' "
                             f"knots) in {name}, got {kind!r}")
    if bases[0].degree != bases[1].degree:
        raise InputError(f"a trimmed surface needs one degree in u and v, got "
                         f"{bases[0].degree} and {bases[1].degree}")
    return Grid((bases[0].cells, bases[1].cells), (bases[0].length, bases[1].length))


def checked_trim(surface: Any, domain: Any) -> TrimDomain:
    """``domain`` if it is a :class:`TrimDomain` whose loops all lie inside the parameter
    rectangle of ``surface`` (:func:`loop_outside`), on a surface that can be trimmed
    (:func:`trim_grid`)."""
    trim_grid(surface)
    if not isinstance(domain, TrimDomain):
        raise InputError(f"a surface's trim must be a splinedeform.trim.TrimDomain, got "
                         f"{type(domain).__name__}")
    for k, loop in enumerate(domain.loops):
        problem = loop_outside(surface, loop)
        if problem:
            raise InputError(f"trim loop {'the outer loop' if k == 0 else f'hole {k}'} "
                             f"{problem}")
    return domain
