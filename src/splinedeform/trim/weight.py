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
