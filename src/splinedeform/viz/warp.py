"""The warp factor of the pictures: displacements drawn larger than they are.

A picture draws ``x_rest + w (x - x_rest)``: with ``w = 1`` the true shape, with ``w > 1``
the displacement exaggerated ``w`` times (colours keep the true ``|x - x_rest|``). The
automatic factor makes the largest displacement :data:`WARP_TARGET` of the surface's size,
rounded down to 1, 2 or 5 × 10ᵏ (so it is drawn as 8 % to 20 % of the size), and never
shrinks a displacement (``w >= 1``).
"""

from __future__ import annotations

import math

from ..errors import InputError

#: "auto": the largest displacement is drawn as this fraction of the surface's size
WARP_TARGET = 0.2


def auto_warp(largest_displacement: float, size: float) -> float:
    """``w = max(1, nice(WARP_TARGET · size / max |d|))``, ``nice`` rounding down to 1, 2, 5 × 10ᵏ.

    ``size`` is the diameter of the rest surface's bounding box; a surface that does not
    move (``max |d| = 0``) gets 1.
    """
    d, L = float(largest_displacement), float(size)
    if not (math.isfinite(d) and math.isfinite(L)) or d < 0 or L < 0:
        raise InputError(f"warp needs a finite displacement and size >= 0, got {d!r}, {L!r}")
    if d == 0 or L == 0 or d >= WARP_TARGET * L:
        return 1.0
    raw = WARP_TARGET * L / d
    decade = 10.0 ** math.floor(math.log10(raw) + 1e-12)
    mantissa = max(m for m in (1.0, 2.0, 5.0, 10.0) if m * decade <= raw * (1 + 1e-12))
    return max(1.0, mantissa * decade)


def warp_caption(warp: float) -> str:
    """What a picture says of its warp factor: empty at true scale."""
    return "" if warp == 1 else f"displacement drawn × {warp:g} (output.warp)"
