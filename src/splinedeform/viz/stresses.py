"""``stresses.png``: a shell's deformed surface coloured by its von Mises stress.

Two panels, the top (``ζ = t/2``, the side the normal points to) and the bottom face, on
one colour scale ``[0, max σ_vM]`` over both, drawn on the deformed shape at true scale
(matplotlib, as :func:`~splinedeform.viz.surfaces.surfaces_figure`). Points where the
stress is undefined (a pole) are coloured as zero.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InputError
from ..surface import grid_faces
from .figures import (COLORBAR_INCHES, PANEL_INCHES, _axes3d, _axis_labels, _box, _collection,
                      _colorbar, _face_colors, _figure, _save_png)


def stress_figure(X: NDArray[np.float64], faces: NDArray[np.int64],
                  fields: dict[str, NDArray[np.float64]], title: str) -> Any:
    """Figure with one panel per field (per-vertex values on the mesh ``X``), shared scale."""
    values = {k: np.nan_to_num(np.asarray(v, dtype=float), nan=0.0) for k, v in fields.items()}
    vmax = max(float(v.max(initial=0.0)) for v in values.values())
    n = len(values)
    width = PANEL_INCHES * n + COLORBAR_INCHES
    fig = _figure(width, PANEL_INCHES)
    for i, (label, value) in enumerate(values.items()):
        ax = _axes3d(fig, [i * PANEL_INCHES / width, 0.02, PANEL_INCHES / width, 0.9])
        ax.add_collection3d(_collection(X, faces, _face_colors(value, faces, vmax or 1.0)))
        _box(ax, X)
        _axis_labels(ax)
        ax.set_title(f"{title}: {label}", fontsize=10)
    _colorbar(fig, [(n * PANEL_INCHES + 0.45) / width, 0.12, 0.18 / width, 0.72],
              vmax, label="von Mises stress")
    return fig


def render_stresses(path: str | os.PathLike[str], model: Any, rest_net: ArrayLike,
                    net: ArrayLike, title: str, resolution: int = 48) -> Path:
    """PNG of the shell ``model`` in the state ``net``, coloured by von Mises top and bottom."""
    target = Path(path)
    if target.suffix.lower() != ".png":
        raise InputError(f"render_stresses writes PNG; got {target.name!r}")
    surface = model.surface
    u, v = surface.sample_parameters(int(resolution))
    U, V = np.meshgrid(u, v, indexing="ij")
    rest = np.asarray(rest_net, dtype=float)
    s = model.stresses(np.asarray(net, dtype=float) - rest, U, V, at_poles="nan")
    X = surface.with_control_points(np.asarray(net, dtype=float)).evaluate(U, V).reshape(-1, 3)
    fields = {f"{layer} face": s.von_mises[layer].ravel() for layer in ("top", "bottom")}
    return _save_png(stress_figure(X, grid_faces(u.size, v.size), fields, title), target)
