"""The warp factor of the pictures: displacements drawn larger than they are.

A picture draws ``x_rest + w (x - x_rest)``: with ``w = 1`` the true shape, with ``w > 1``
the displacement exaggerated ``w`` times (colours keep the true ``|x - x_rest|``). The
automatic factor makes the largest displacement :data:`WARP_TARGET` of the surface's size,
rounded to the nearest (in ratio) of 1, 2, 5 × 10ᵏ (so it is drawn as 13 % to 28 % of the
size), when the largest displacement is under :data:`VISIBLE` of the size; a displacement
that large is drawn as it is (``w = 1``).
"""

from __future__ import annotations

import math

from ..errors import InputError

#: "auto": the largest displacement is drawn as this fraction of the surface's size
WARP_TARGET = 0.2
#: "auto" leaves displacements of at least this fraction of the size at true scale
VISIBLE = 0.05


def auto_warp(largest_displacement: float, size: float) -> float:
    """``w = max(1, nice(WARP_TARGET · size / max |d|))``, ``nice`` the nearest of 1, 2, 5 × 10ᵏ
    in ratio (least ``|log(w / raw)|``; ties go to the smaller).

    ``size`` is the largest side of the rest surface's bounding box; a surface that does not
    move (``max |d| = 0``), or whose largest displacement is ``VISIBLE · size`` or more,
    gets 1.
    """
    d, L = float(largest_displacement), float(size)
    if not (math.isfinite(d) and math.isfinite(L)) or d < 0 or L < 0:
        raise InputError(f"warp needs a finite displacement and size >= 0, got {d!r}, {L!r}")
    if d == 0 or L == 0 or d >= VISIBLE * L:
        return 1.0
    raw = WARP_TARGET * L / d
    decade = 10.0 ** math.floor(math.log10(raw))
    candidates = [m * decade for m in (1.0, 2.0, 5.0, 10.0)]
    nearest = min(candidates, key=lambda w: (round(abs(math.log(w / raw)), 12), w))
    return max(1.0, nearest)


def warp_caption(warp: float) -> str:
    """What a picture says of its warp factor: empty at true scale."""
    return "" if warp == 1 else f"displacement drawn × {warp:g} (output.warp)"
