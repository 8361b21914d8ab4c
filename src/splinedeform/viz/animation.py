"""Animations of the motion: a looping GIF (imageio + pillow) or an MP4 (imageio-ffmpeg)."""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InputError
from ..export import check_frames, write_with
from ..surface import Surface
from .figures import DPI, _axes3d, _box, _collection, _colorbar, _face_colors, _figure
from .surfaces import _displaced_meshes

ANIMATION_PIXELS = (640, 480)  # divisible by 16 for video encoders

Progress = Callable[[int, int], object] | None


def mp4_available() -> bool:
    """Whether an MP4 encoder (imageio-ffmpeg, the ``video`` extra) can be used."""
    try:
        import imageio_ffmpeg

        return bool(imageio_ffmpeg.get_ffmpeg_exe())
    except Exception:   # noqa: BLE001  (missing package or missing binary)
        return False


def animation_frames(surface: Surface, rest_net: ArrayLike, times: ArrayLike, nets: ArrayLike,
                     resolution: int = 32, progress: Progress = None
                     ) -> list[NDArray[np.uint8]]:
    """RGB images ``(480, 640, 3)`` of every frame, with fixed axes and colour scale."""
    t, P = check_frames(surface, times, nets)
    X, mag, faces = _displaced_meshes(surface, rest_net, list(P), resolution)
    vmax = float(mag.max())
    width, height = ANIMATION_PIXELS
    fig = _figure(width / DPI, height / DPI)
    ax = _axes3d(fig, [0.0, 0.02, 0.84, 0.9])
    _box(ax, X)
    _colorbar(fig, [0.86, 0.15, 0.025, 0.7], vmax)
    images = []
    collection = None
    for f in range(t.size):
        if collection is not None:
            collection.remove()
        collection = _collection(X[f], faces, _face_colors(mag[f], faces, vmax))
        ax.add_collection3d(collection)
        ax.set_title(f"t = {t[f]:.4g}", fontsize=11)
        fig.canvas.draw()
        images.append(np.asarray(fig.canvas.buffer_rgba())[..., :3].copy())
        if progress is not None:
            progress(f + 1, t.size)
    return images


def write_animation(path: str | os.PathLike[str], surface: Surface, rest_net: ArrayLike,
                    times: ArrayLike, nets: ArrayLike, resolution: int = 32,
                    progress: Progress = None, fps: float = 15.0) -> Path:
    """Animate the motion as a looping GIF (imageio + pillow) or an MP4 (imageio-ffmpeg).

    One 640 × 480 image per frame (see :func:`animation_frames`), ``fps`` frames per
    second. ``progress(done, total)`` is called after each rendered frame.
    """
    import imageio.v3 as iio

    target = Path(path)
    suffix = target.suffix.lower()
    if suffix not in (".gif", ".mp4"):
        raise InputError(f"animations are written as .gif or .mp4, got {target.name!r}")
    if not (np.isfinite(fps) and fps > 0):
        raise InputError(f"fps must be finite and > 0, got {fps!r}")
    if suffix == ".mp4" and not mp4_available():
        raise InputError("MP4 needs an ffmpeg encoder: install the extra `video` "
                         "(pip install 'splinedeform[video]') or write a .gif")
    check_frames(surface, times, nets)
    images = np.stack(animation_frames(surface, rest_net, times, nets, resolution, progress))
    if suffix == ".gif":
        return write_with(target, lambda tmp: iio.imwrite(
            tmp, images, extension=".gif", duration=1000.0 / fps, loop=0))
    return write_with(target, lambda tmp: _write_mp4(tmp, images, fps))


def _write_mp4(path: Path, images: NDArray[np.uint8], fps: float) -> None:
    import imageio.v2 as iio2

    writer = iio2.get_writer(path, format="FFMPEG", mode="I", fps=fps, codec="libx264",
                             quality=7, macro_block_size=16, ffmpeg_log_level="error")
    try:
        for image in images:
            writer.append_data(image)
    finally:
        writer.close()

