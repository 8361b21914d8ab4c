"""Colour of a displacement and the two-sided Lambert shading of the pictures.

Colour encodes the displacement magnitude ``|d| = |x - x_rest|`` sampled on the
tessellation grid, mapped linearly to the perceptually uniform ``plasma`` colormap
(dark blue at ``|d| = 0``, bright yellow at the largest displacement shown), the same in
the PNGs, the animation and the viewer's legend.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InputError

COLORMAP = "plasma"
MODE_COLORMAP = "coolwarm"
LIGHT = np.array([0.3, -0.5, 0.8]) / np.linalg.norm([0.3, -0.5, 0.8])


def displacement_colors(magnitude: ArrayLike, vmax: float | None = None) -> NDArray[np.float64]:
    """RGBA colours of displacement magnitudes: ``plasma(clip(|d| / vmax, 0, 1))``.

    ``vmax`` defaults to ``max |d|``; when it is 0 every value gets the low end.
    Returns an array of shape ``magnitude.shape + (4,)``.
    """
    import matplotlib

    m = np.asarray(magnitude, dtype=float)
    if not np.all(np.isfinite(m)) or np.any(m < 0):
        raise InputError("displacement magnitudes must be finite and >= 0")
    top = float(m.max()) if vmax is None and m.size else float(vmax or 0.0)
    if not np.isfinite(top) or top < 0:
        raise InputError(f"vmax must be finite and >= 0, got {vmax!r}")
    scaled = m / top if top > 0 else np.zeros_like(m)
    return np.asarray(matplotlib.colormaps[COLORMAP](np.clip(scaled, 0.0, 1.0)))


def colormap_table(n: int = 256) -> list[list[int]]:
    """The colormap as ``n`` RGB byte triples (for the viewer's shader and legend)."""
    rgba = displacement_colors(np.linspace(0.0, 1.0, n), 1.0)
    return (rgba[:, :3] * 255).round().astype(int).tolist()


def shade(rgba: NDArray[np.float64], normals: NDArray[np.float64], ambient: float = 0.55
          ) -> NDArray[np.float64]:
    """Two-sided Lambert shading ``rgb · (a + (1 - a) |n · l|)`` with a fixed light ``l``.

    ``a`` is the ambient share (0.55 by default: colours stay readable against the
    colour bar; the grey rest shape uses less, so its form shows).
    """
    length = np.linalg.norm(normals, axis=-1, keepdims=True)
    n = np.divide(normals, length, out=np.zeros_like(normals), where=length > 0)
    factor = ambient + (1.0 - ambient) * np.abs(n @ LIGHT)
    out = rgba.copy()
    out[..., :3] *= factor[..., None]
    return out
