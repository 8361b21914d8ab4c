"""Weight functions for essential boundary conditions on a trimmed region.

A weight ``w`` is smooth, positive in ``Ω`` and vanishes on the held boundary; the
basis ``w^p B_i`` then vanishes there (``p = 1``: ``d = 0``) and, with ``p = 2``, so does
its normal derivative (``∂_n d = 0``: a clamped edge), since ``∂_n (w² s) = 2 w s ∂_n w = 0``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError
from .loops import CircleLoop, PolygonLoop, TrimDomain


@dataclass(frozen=True)
class DiscWeight:
    """``w(x) = 1 - |x - c|² / a²``: the normalised (``∇w`` of unit size ``2/a`` on the
    circle) polynomial weight of the disc ``|x - c| < a``, raised to ``power``."""

    centre: tuple[float, float]
    radius: float
    power: int = 1

    def __post_init__(self) -> None:
        if not (np.isfinite(self.radius) and self.radius > 0):
            raise InputError(f"weight radius must be finite and > 0, got {self.radius!r}")
        if self.power not in (1, 2):
            raise InputError(f"weight power must be 1 (held edge) or 2 (clamped), got {self.power!r}")

    def derivatives(self, p: NDArray[np.float64]) -> tuple[NDArray[np.float64], ...]:
        """``W, W_x, W_y, W_xx, W_xy, W_yy`` of ``W = w^power`` at points ``(Q, 2)``.

        Chain rule: ``W_x = p w^{p-1} w_x``, ``W_xy = p(p-1) w^{p-2} w_x w_y + p w^{p-1} w_xy``.
        """
        a2 = self.radius ** 2
        x, y = p[:, 0] - self.centre[0], p[:, 1] - self.centre[1]
        w = 1 - (x * x + y * y) / a2
        wx, wy = -2 * x / a2, -2 * y / a2
        wxx = wyy = np.full_like(x, -2 / a2)
        wxy = np.zeros_like(x)
        if self.power == 1:
            return w, wx, wy, wxx, wxy, wyy
        return (w * w, 2 * w * wx, 2 * w * wy, 2 * wx * wx + 2 * w * wxx,
                2 * wx * wy + 2 * w * wxy, 2 * wy * wy + 2 * w * wyy)

    def __call__(self, p: NDArray[np.float64]) -> NDArray[np.float64]:
        return self.derivatives(p)[0]


Jet = tuple[NDArray[np.float64], ...]
"""A function and its derivatives ``(f, f_x, f_y, f_xx, f_xy, f_yy)`` at points."""


def _r_join(f: Jet, g: Jet, sign: float) -> Jet:
    """Rvachev's R-conjunction (``sign = -1``) or R-disjunction (``sign = +1``):

    ``f ∧ g = f + g - √(f² + g²)``, ``f ∨ g = f + g + √(f² + g²)``, with derivatives by
    the chain rule, ``∂_a s = (f f_a + g g_a)/s``,
    ``∂_ab s = (f_a f_b + f f_ab + g_a g_b + g g_ab)/s - ∂_a s ∂_b s / s``.
    """
    s = np.sqrt(f[0] ** 2 + g[0] ** 2)
    s = np.where(s > 0, s, np.finfo(float).tiny)
    sx = (f[0] * f[1] + g[0] * g[1]) / s
    sy = (f[0] * f[2] + g[0] * g[2]) / s
    sxx = (f[1] ** 2 + f[0] * f[3] + g[1] ** 2 + g[0] * g[3]) / s - sx * sx / s
    sxy = (f[1] * f[2] + f[0] * f[4] + g[1] * g[2] + g[0] * g[4]) / s - sx * sy / s
    syy = (f[2] ** 2 + f[0] * f[5] + g[2] ** 2 + g[0] * g[5]) / s - sy * sy / s
    return tuple(a + b + sign * c for a, b, c in zip(f, g, (s, sx, sy, sxx, sxy, syy)))


@dataclass(frozen=True)
class RvachevWeight:
    """A normalised distance weight of a region bounded by convex polygons and circles.

    Each loop gives a function of unit slope on its curve, positive on the region's side:
    a counter-clockwise edge ``a → b`` the signed distance to its line
    ``ℓ(x) = ((b - a) × (x - a)) / |b - a|``, a circle ``(r² - |x - c|²)/(2r)`` (negated for a
    hole). The edges of an outer polygon are joined by R-conjunction, those of a
    clockwise (hole) polygon by R-disjunction, and the loops by R-conjunction; the result
    vanishes exactly on the loops, is positive inside and has ``|∇w| = 1`` on the loops
    away from corners. Raised to ``power`` (1 or 2) by the chain rule.

    Where two edges meet, ``√(f² + g²) → 0`` and the second derivatives grow like ``1/r``:
    the weight suits second-order problems there, not plates.
    """

    domain: TrimDomain
    power: int = 1

    def __post_init__(self) -> None:
        if self.power not in (1, 2):
            raise InputError(f"weight power must be 1 (held edge) or 2 (clamped), got {self.power!r}")
        for loop in self.domain.loops:
            if not isinstance(loop, (PolygonLoop, CircleLoop)):
                raise InputError("the Rvachev weight is written for polygon and circle loops, "
                                 f"not for a {type(loop).__name__}")
            if isinstance(loop, PolygonLoop):
                v = loop.vertices
                e = np.roll(v, -1, axis=0) - v
                turn = e[:, 0] * np.roll(e[:, 1], -1) - e[:, 1] * np.roll(e[:, 0], -1)
                if not (np.all(turn >= 0) or np.all(turn <= 0)):
                    raise InputError("the Rvachev weight needs convex polygon loops; "
                                     "a loop of the trim region is not convex")

    def derivatives(self, p: NDArray[np.float64]) -> Jet:
        """``W, W_x, W_y, W_xx, W_xy, W_yy`` of ``W = w^power`` at points ``(Q, 2)``."""
        zero = np.zeros(len(p))
        total: Jet | None = None
        for loop in self.domain.loops:
            if isinstance(loop, CircleLoop):
                x, y = p[:, 0] - loop.centre[0], p[:, 1] - loop.centre[1]
                r, k = loop.radius, float(loop.sense)
                part: Jet = (k * (r * r - x * x - y * y) / (2 * r), -k * x / r, -k * y / r,
                             np.full(len(p), -k / r), zero, np.full(len(p), -k / r))
            else:
                a, b = loop.segments()
                part = None                                      # type: ignore[assignment]
                for start, end in zip(a, b):
                    d = (end - start) / np.hypot(*(end - start))
                    line = (d[0] * (p[:, 1] - start[1]) - d[1] * (p[:, 0] - start[0]),
                            np.full(len(p), -d[1]), np.full(len(p), d[0]), zero, zero, zero)
                    part = line if part is None else _r_join(part, line,
                                                             -1.0 if loop.signed_area > 0 else 1.0)
            total = part if total is None else _r_join(total, part, -1.0)
        assert total is not None
        w, wx, wy, wxx, wxy, wyy = total
        if self.power == 1:
            return total
        return (w * w, 2 * w * wx, 2 * w * wy, 2 * wx * wx + 2 * w * wxx,
                2 * wx * wy + 2 * w * wxy, 2 * wy * wy + 2 * w * wyy)

    def __call__(self, p: NDArray[np.float64]) -> NDArray[np.float64]:
        return self.derivatives(p)[0]
