"""surfaces.png: panels of the surface coloured by displacement on a shared scale.

If PyVista is importable and can render off screen, :func:`render_surfaces` uses it;
otherwise, or if it fails for any reason, matplotlib draws the same picture without a
message.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InputError
from ..export import check_net, tessellate_frames, weld, write_with
from ..surface import Surface
from .colour import COLORMAP
from .figures import (CAMERA, COLORBAR_INCHES, DPI, PANEL_INCHES, REST_RGBA, _axes3d, _axis_labels,
                      _box, _collection, _colorbar, _face_colors, _figure, _save_png)
from .warp import warp_caption


def _displaced_meshes(surface: Surface, rest_net: ArrayLike, nets: Sequence[ArrayLike],
                      resolution: int, warp: float = 1.0
                      ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.int64]]:
    """Drawn vertices ``x_rest + w d`` ``(F, N, 3)``, true ``|d|`` ``(F, N)`` and faces.

    Welded (:func:`~splinedeform.export.weld`): seams and poles are one vertex and the
    zero-area triangles of a pole, whose normal is undefined, are not drawn.
    """
    P = np.stack([check_net(surface, net, f"nets[{i}]") for i, net in enumerate(nets)])
    rest = check_net(surface, rest_net, "rest net")
    X, faces = tessellate_frames(surface, P, resolution)
    X0, _ = tessellate_frames(surface, rest, resolution)
    keep, faces = weld(np.concatenate([X0[None], X]), faces)
    X, X0 = X[:, keep], X0[keep]
    return X0 + warp * (X - X0), np.linalg.norm(X - X0, axis=-1), faces


def _pyvista() -> Any:
    """The pyvista module if it is installed, else None."""
    try:
        import pyvista
    except Exception:   # noqa: BLE001  (any import failure means: not available)
        return None
    return pyvista


def _render_pyvista(path: Path, X: NDArray[np.float64], mag: NDArray[np.float64],
                    faces: NDArray[np.int64], titles: Sequence[str], vmax: float,
                    caption: str = "") -> Path:
    pv = _pyvista()
    if pv is None:
        raise RuntimeError("pyvista is not installed")
    n = X.shape[0]
    size = (int(PANEL_INCHES * DPI) * n + int(COLORBAR_INCHES * DPI), int(PANEL_INCHES * DPI))
    plotter = pv.Plotter(off_screen=True, shape=(1, n), window_size=size, border=False)
    try:
        cells = np.hstack([np.full((faces.shape[0], 1), 3), faces]).ravel()
        for i in range(n):
            plotter.subplot(0, i)
            mesh = pv.PolyData(X[i], cells)
            mesh.point_data["|displacement|"] = mag[i]
            plotter.add_mesh(mesh, scalars="|displacement|", cmap=COLORMAP,
                             clim=(0.0, vmax if vmax > 0 else 1.0), show_scalar_bar=i == n - 1)
            plotter.add_text(titles[i], font_size=10)
            if caption and i == n - 1:
                plotter.add_text(caption, position="lower_left", font_size=8)
            plotter.view_isometric()
        plotter.link_views()
        return write_with(path, lambda tmp: plotter.screenshot(str(tmp)))
    finally:
        plotter.close()


def surfaces_figure(X: NDArray[np.float64], mag: NDArray[np.float64],
                    faces: NDArray[np.int64], titles: Sequence[str], vmax: float,
                    camera: tuple[float, float] = CAMERA, warp: float = 1.0) -> Any:
    """The matplotlib Figure of :func:`render_surfaces` (one 3-D axes per panel).

    Each surface is one collection of triangles, drawn far to near in the order of the
    depth of their projected centroids (painter's order), shaded by
    :func:`~splinedeform.viz.colour.shade`. A panel without displacement (the rest shape)
    is drawn in a neutral grey, so its shading shows the shape rather than a flat navy.
    A warp factor ``warp`` other than 1 is written under the colour bar.
    """
    n = X.shape[0]
    width = PANEL_INCHES * n + COLORBAR_INCHES
    fig = _figure(width, PANEL_INCHES)
    for i in range(n):
        ax = _axes3d(fig, [i * PANEL_INCHES / width, 0.02, PANEL_INCHES / width, 0.9], camera)
        at_rest = not mag[i].max() > 1e-12 * vmax
        rgba = np.tile(REST_RGBA, (faces.shape[0], 1)) if at_rest \
            else _face_colors(mag[i], faces, vmax)
        ax.add_collection3d(_collection(X[i], faces, rgba, ambient=0.3 if at_rest else 0.55))
        _box(ax, X)
        _axis_labels(ax)
        ax.set_title(titles[i], fontsize=10)
    _colorbar(fig, [(n * PANEL_INCHES + 0.45) / width, 0.12, 0.18 / width, 0.72], vmax)
    if warp != 1:
        fig.text((n * PANEL_INCHES + 0.54) / width, 0.015, f"displacement\ndrawn × {warp:g}",
                 fontsize=8, ha="center", va="bottom")
    return fig


def _render_matplotlib(path: Path, X: NDArray[np.float64], mag: NDArray[np.float64],
                       faces: NDArray[np.int64], titles: Sequence[str], vmax: float,
                       camera: tuple[float, float], warp: float) -> Path:
    return _save_png(surfaces_figure(X, mag, faces, titles, vmax, camera, warp), path)


def render_surfaces(path: str | os.PathLike[str], surface: Surface, rest_net: ArrayLike,
                    nets: Sequence[ArrayLike], titles: Sequence[str], resolution: int = 48,
                    warp: float = 1.0, camera: tuple[float, float] = CAMERA) -> Path:
    """PNG with one panel per control net, coloured by ``|x - x_rest|`` on a shared scale.

    All panels share the colour scale ``[0, max |d|]`` and the same equal-aspect box, so
    sizes and colours compare across panels; a panel with no displacement is grey. With
    matplotlib the picture is ``(400 n + 150) × 400`` pixels for ``n`` panels. Each panel
    draws ``x_rest + w d`` with the warp factor ``w`` (stated under the colour bar when it
    is not 1; colours keep the true ``|d|``), seen from ``camera = (elevation, azimuth)``
    in degrees (matplotlib; PyVista keeps its isometric view).
    """
    target = Path(path)
    if target.suffix.lower() != ".png":
        raise InputError(f"render_surfaces writes PNG; got {target.name!r}")
    if isinstance(nets, np.ndarray) and nets.ndim == 3:
        nets = [nets]
    if len(nets) == 0 or len(nets) != len(titles):
        raise InputError(f"give one title per net and at least one net; got {len(nets)} net(s) "
                         f"and {len(titles)} title(s)")
    if not (isinstance(warp, (int, float)) and np.isfinite(warp) and warp > 0):
        raise InputError(f"warp must be finite and > 0, got {warp!r}")
    X, mag, faces = _displaced_meshes(surface, rest_net, nets, resolution, float(warp))
    return _render(target, X, mag, faces, titles, float(warp), camera)


def render_body_surfaces(path: str | os.PathLike[str], patches: Sequence[Surface],
                         rest_nets: Sequence[ArrayLike], nets: Sequence[Sequence[ArrayLike]],
                         titles: Sequence[str], resolution: int = 48, warp: float = 1.0,
                         camera: tuple[float, float] = CAMERA) -> Path:
    """:func:`render_surfaces` of a body: every patch drawn in every panel.

    ``nets[i]`` holds panel ``i``'s net of each patch. The patches are sampled on their
    ``r × r`` grids and welded where they meet (:func:`splinedeform.export.welded_body`),
    so a panel is one mesh of the whole body coloured by ``|x - x_rest|``.
    """
    target = Path(path)
    if target.suffix.lower() != ".png":
        raise InputError(f"render_body_surfaces writes PNG; got {target.name!r}")
    if len(nets) == 0 or len(nets) != len(titles):
        raise InputError(f"give one title per panel and at least one panel; got {len(nets)} "
                         f"panel(s) and {len(titles)} title(s)")
    if not (isinstance(warp, (int, float)) and np.isfinite(warp) and warp > 0):
        raise InputError(f"warp must be finite and > 0, got {warp!r}")
    frames = [np.stack([np.asarray(panel[k], dtype=float) for panel in nets])
              for k in range(len(rest_nets))]
    X, mag, faces = body_displaced_meshes(patches, rest_nets, frames, resolution, float(warp))
    return _render(target, X, mag, faces, [str(t) for t in titles], float(warp), camera)


def body_displaced_meshes(patches: Sequence[Surface], rest_nets: Sequence[ArrayLike],
                          frames: Sequence[ArrayLike], resolution: int, warp: float = 1.0
                          ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.int64]]:
    """:func:`_displaced_meshes` of a body: ``frames[k]`` ``(F, n_u, n_v, 3)`` are patch
    ``k``'s nets; the patches' grids welded where they meet at rest and in every frame
    (:func:`splinedeform.export.body.welded_body`), so each frame is one mesh."""
    from ..export.body import welded_body

    stacked = [np.concatenate([np.asarray(rest, dtype=float)[None], np.asarray(P, dtype=float)])
               for rest, P in zip(rest_nets, frames)]
    X, faces, _ = welded_body(patches, stacked, resolution)
    d = X[1:] - X[0]
    return X[0] + warp * d, np.linalg.norm(d, axis=-1), faces


def _render(target: Path, X: NDArray[np.float64], mag: NDArray[np.float64],
            faces: NDArray[np.int64], titles: Sequence[str], warp: float,
            camera: tuple[float, float]) -> Path:
    """The picture of drawn panels ``X`` coloured by ``mag``, PyVista else matplotlib."""
    vmax = float(mag.max())
    titles = [str(t) for t in titles]
    caption = warp_caption(warp)
    if _pyvista() is not None:
        try:
            return _render_pyvista(target, X, mag, faces, titles, vmax, caption)
        except Exception:   # noqa: BLE001  (no off-screen context: draw with matplotlib)
            pass
    return _render_matplotlib(target, X, mag, faces, titles, vmax, camera, warp)

