"""matplotlib helpers shared by the pictures and the animation (Agg canvas, no pyplot)."""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError
from ..export import write_with
from .colour import COLORMAP, displacement_colors, shade

#: version of what the pictures show: raise it with any change that alters them (view,
#: colours, layout, warp); docs/gallery/regenerate.py records it in the gallery's
#: manifest and tests/test_gallery.py asks for the gallery to be regenerated when it differs
RENDERER_VERSION = 2

DPI = 100
PANEL_INCHES = 4.0          # each surface panel is 400 × 400 px
COLORBAR_INCHES = 1.5     # colour bar and its label, clear of the last panel's z ticks
#: the view of every 3-D picture: (elevation, azimuth) in degrees (``output.camera``)
CAMERA = (28.0, -60.0)
#: base colour of a panel without displacement (the rest shape), shaded like the others
REST_RGBA = np.array([0.78, 0.80, 0.84, 1.0])


def _figure(width: float, height: float) -> Any:
    """A matplotlib Figure on an Agg canvas (no global pyplot state, no display)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(width, height), dpi=DPI)
    FigureCanvasAgg(fig)
    return fig


#: white kept around the drawing when a picture's margins are trimmed
MARGIN_PIXELS = 10


def _save_png(fig: Any, path: str | os.PathLike[str], trim: bool = False) -> Path:
    """Write ``fig`` as PNG; with ``trim`` the white border is cut to :data:`MARGIN_PIXELS`."""
    target = Path(path)
    if target.suffix.lower() != ".png":
        raise InputError(f"pictures are written as PNG; the file name must end in .png, "
                         f"got {target.name!r}")
    if not trim:
        return write_with(target, lambda tmp: fig.savefig(tmp, format="png", dpi=DPI))
    from PIL import Image

    fig.canvas.draw()
    rgb = np.asarray(fig.canvas.buffer_rgba())[..., :3]
    ink = np.any(rgb < 250, axis=-1)
    rows, cols = np.flatnonzero(ink.any(axis=1)), np.flatnonzero(ink.any(axis=0))
    if rows.size:
        top, bottom = max(rows[0] - MARGIN_PIXELS, 0), min(rows[-1] + MARGIN_PIXELS + 1, len(rgb))
        left, right = max(cols[0] - MARGIN_PIXELS, 0), min(cols[-1] + MARGIN_PIXELS + 1,
                                                           rgb.shape[1])
        rgb = rgb[top:bottom, left:right]
    image = Image.fromarray(np.ascontiguousarray(rgb))
    return write_with(target, lambda tmp: image.save(tmp, format="png"))


def _bounds(points: NDArray[np.float64]) -> tuple[NDArray[np.float64], float]:
    """Centre and half-width of the cube that holds ``points (..., 3)``."""
    flat = points.reshape(-1, 3)
    lo, hi = flat.min(axis=0), flat.max(axis=0)
    half = 0.5 * float(np.max(hi - lo))
    return 0.5 * (lo + hi), half if half > 0 else 1.0


def _box(ax: Any, points: NDArray[np.float64], zoom: float = 1.0) -> None:
    """Equal aspect: the tight box around ``points``, padded where it is flat."""
    flat = points.reshape(-1, 3)
    lo, hi = flat.min(axis=0), flat.max(axis=0)
    pad = np.maximum(hi - lo, 0.05 * max(float(np.max(hi - lo)), 1e-12)) / 2
    centre = 0.5 * (lo + hi)
    ax.set_xlim(centre[0] - pad[0], centre[0] + pad[0])
    ax.set_ylim(centre[1] - pad[1], centre[1] + pad[1])
    ax.set_zlim(centre[2] - pad[2], centre[2] + pad[2])
    ax.set_box_aspect(tuple(2 * pad), zoom=zoom)
    from matplotlib.ticker import MaxNLocator

    for axis, extent in zip((ax.xaxis, ax.yaxis, ax.zaxis), pad / pad.max()):
        if extent < 0.15:            # a thin side of the box has no room for tick labels
            axis.set_ticks([])
        elif extent < 0.4:
            axis.set_major_locator(MaxNLocator(3))


def _collection(vertices: NDArray[np.float64], faces: NDArray[np.int64],
                face_rgba: NDArray[np.float64], ambient: float = 0.55) -> Any:
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    triangles = vertices[faces]
    normals = np.cross(triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0])
    rgba = shade(face_rgba, normals, ambient)
    # edges in the face colour close the hairline gaps between antialiased triangles
    return Poly3DCollection(triangles, facecolors=rgba, edgecolors=rgba, linewidths=0.3)


def _face_colors(magnitude: NDArray[np.float64], faces: NDArray[np.int64], vmax: float
                 ) -> NDArray[np.float64]:
    return displacement_colors(magnitude[faces].mean(axis=1), vmax)


def _axes3d(fig: Any, rect: Sequence[float] | tuple[int, int, int],
            camera: tuple[float, float] = CAMERA) -> Any:
    import mpl_toolkits.mplot3d  # noqa: F401  (registers the 3-D projection)

    ax = fig.add_axes(rect, projection="3d") if len(rect) == 4 else \
        fig.add_subplot(*rect, projection="3d")
    ax.view_init(elev=float(camera[0]), azim=float(camera[1]))
    ax.tick_params(labelsize=7, pad=0)
    return ax


def _axis_labels(ax: Any) -> None:
    """``x``, ``y``, ``z`` on the three axes (also where a thin side has no ticks)."""
    for setter, name in ((ax.set_xlabel, "x"), (ax.set_ylabel, "y"), (ax.set_zlabel, "z")):
        setter(name, fontsize=9, labelpad=-4)


def _colorbar(fig: Any, rect: Sequence[float], vmax: float, label: str = "|displacement|",
              levels: int | None = None, colormap: str = COLORMAP, vmin: float = 0.0) -> Any:
    """A vertical colour bar of ``colormap`` over ``[vmin, vmax]``; ``levels`` draws it
    with the map resampled at that many colours (as a GIF palette holds them)."""
    import matplotlib
    from matplotlib.cm import ScalarMappable
    from matplotlib.colors import Normalize

    cmap = matplotlib.colormaps[colormap]
    top = vmax if vmax > vmin else vmin + 1.0
    mappable = ScalarMappable(Normalize(vmin, top),
                              cmap.resampled(levels) if levels is not None else cmap)
    bar = fig.colorbar(mappable, cax=fig.add_axes(rect))
    bar.set_label(label)
    return bar

