"""Animations of the motion: a looping GIF (pillow, :mod:`.gif`) or an MP4 (imageio-ffmpeg).

Frames are drawn one at a time on one matplotlib figure (fixed axes, colour scale and
view) and written as they are drawn, so memory holds a few frames (the GIF's palette
samples), not the whole film, and the progress counts frames written.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InputError
from ..export import check_frames, write_with
from ..surface import Surface
from .colour import COLORMAP
from .figures import CAMERA, DPI, _axes3d, _box, _collection, _colorbar, _face_colors, _figure
from .gif import RAMP_LEVELS, GifWriter, PaletteMap, global_palette, ramp_colors
from .surfaces import _displaced_meshes
from .warp import warp_caption

ANIMATION_PIXELS = (640, 480)  # divisible by 16 for video encoders
#: frames sampled (besides the peak) to fit the GIF's palette
PALETTE_SAMPLES = 5

Progress = Callable[[int, int], object] | None


def mp4_available() -> bool:
    """Whether an MP4 encoder (imageio-ffmpeg, the ``video`` extra) can be used."""
    try:
        import imageio_ffmpeg

        return bool(imageio_ffmpeg.get_ffmpeg_exe())
    except Exception:   # noqa: BLE001  (missing package or missing binary)
        return False


class _FrameDrawer:
    """Draws frame ``f`` of the motion as an RGB image ``(480, 640, 3)``.

    Vertices ``x_rest + w (x_f - x_rest)`` (warp ``w``), coloured by the true ``|d_f|`` on
    the scale ``[0, max_f |d_f|]``; the colour bar uses the colour map at ``bar_levels``
    levels (the GIF palette holds exactly those). What is the same in every frame (axes,
    panes, ticks, colour bar: three quarters of a full draw) is drawn once and kept as a
    background; each frame restores it and draws only the surface, depth-sorted in the
    fixed view, and its title.
    """

    def __init__(self, t: NDArray[np.float64], meshes: tuple[NDArray[np.float64],
                 NDArray[np.float64], NDArray[np.int64]], warp: float,
                 camera: tuple[float, float], bar_levels: int | None = None,
                 label: str = "t") -> None:
        self.t = t
        self.X, self.mag, self.faces = meshes       # drawn vertices, |d| and faces per frame
        self.vmax = float(self.mag.max())
        self.caption, self.label = warp_caption(warp), str(label)
        width, height = ANIMATION_PIXELS
        self.fig = _figure(width / DPI, height / DPI)
        self.ax = _axes3d(self.fig, [0.0, 0.02, 0.84, 0.9], camera)
        _box(self.ax, self.X)
        _colorbar(self.fig, [0.86, 0.15, 0.025, 0.7], self.vmax, levels=bar_levels)
        self.ax.set_title(" ", fontsize=11)
        self.fig.canvas.draw()                      # also sets the view's projection ax.M
        self._background = self.fig.canvas.copy_from_bbox(self.fig.bbox)

    @property
    def peak(self) -> int:
        """The frame of largest displacement (the first such)."""
        return int(np.argmax(self.mag.max(axis=1)))

    def __len__(self) -> int:
        return int(self.t.size)

    def __call__(self, f: int) -> NDArray[np.uint8]:
        canvas = self.fig.canvas
        canvas.restore_region(self._background)
        surface = _collection(self.X[f], self.faces,
                              _face_colors(self.mag[f], self.faces, self.vmax))
        self.ax.add_collection3d(surface)
        try:
            surface.do_3d_projection()              # painter's order in the fixed view
            self.ax.draw_artist(surface)
        finally:
            surface.remove()
        title = f"{self.label} = {self.t[f]:.4g}" + (f"  ·  {self.caption}" if self.caption
                                                      else "")
        self.ax.title.set_text(title)
        self.ax.draw_artist(self.ax.title)
        return np.asarray(canvas.buffer_rgba())[..., :3].copy()


def animation_frames(surface: Surface, rest_net: ArrayLike, times: ArrayLike, nets: ArrayLike,
                     resolution: int = 32, progress: Progress = None, warp: float = 1.0,
                     camera: tuple[float, float] = CAMERA, label: str = "t"
                     ) -> list[NDArray[np.uint8]]:
    """RGB images ``(480, 640, 3)`` of every frame, with fixed axes and colour scale.

    ``warp`` scales the drawn displacement (``x_rest + w d``; colours keep ``|d|``),
    ``camera`` is the view ``(elevation, azimuth)`` in degrees; each frame is titled
    ``"{label} = {time}"``.
    """
    t, P = check_frames(surface, times, nets)
    draw = _FrameDrawer(t, _displaced_meshes(surface, rest_net, list(P), resolution, warp),
                        warp, camera, None, label)
    images = []
    for f in range(len(draw)):
        images.append(draw(f))
        if progress is not None:
            progress(f + 1, len(draw))
    return images


def write_animation(path: str | os.PathLike[str], surface: Surface, rest_net: ArrayLike,
                    times: ArrayLike, nets: ArrayLike, resolution: int = 32,
                    progress: Progress = None, fps: float = 15.0, warp: float = 1.0,
                    camera: tuple[float, float] = CAMERA, label: str = "t") -> Path:
    """Animate the motion as a looping GIF (pillow) or an MP4 (imageio-ffmpeg).

    One 640 × 480 image per frame (see :func:`animation_frames` for ``warp``, ``camera``
    and ``label``), ``fps`` frames per second (a GIF rounds the delay to hundredths of a
    second). ``progress(done, total)`` is called after each frame is drawn and encoded.
    The GIF's palette holds the colour bar's :data:`~splinedeform.viz.gif.RAMP_LEVELS`
    colours exactly (see :mod:`splinedeform.viz.gif`).
    """
    target = _checked_target(path, fps, warp)
    t, P = check_frames(surface, times, nets)
    draw = _FrameDrawer(t, _displaced_meshes(surface, rest_net, list(P), resolution,
                                             float(warp)), float(warp), camera,
                        RAMP_LEVELS if target.suffix.lower() == ".gif" else None, label)
    return _write_film(target, draw, fps, progress)


def write_body_animation(path: str | os.PathLike[str], patches: Sequence[Surface],
                         rest_nets: Sequence[ArrayLike], times: ArrayLike,
                         nets: Sequence[ArrayLike], resolution: int = 32,
                         progress: Progress = None, fps: float = 15.0, warp: float = 1.0,
                         camera: tuple[float, float] = CAMERA, label: str = "t") -> Path:
    """:func:`write_animation` of a body: ``nets[k]`` ``(F, n_u, n_v, 3)`` are patch ``k``'s
    frames, every frame drawn as one welded mesh of the whole body
    (:func:`.surfaces.body_displaced_meshes`)."""
    from .surfaces import body_displaced_meshes

    target = _checked_target(path, fps, warp)
    if len(nets) != len(patches) or len(rest_nets) != len(patches) or not patches:
        raise InputError(f"a body of {len(patches)} patch(es) needs as many rest nets and "
                         f"frame sets, got {len(rest_nets)} and {len(nets)}")
    checked = [check_frames(s, times, P) for s, P in zip(patches, nets)]
    meshes = body_displaced_meshes(patches, rest_nets, [P for _, P in checked], resolution,
                                   float(warp))
    draw = _FrameDrawer(checked[0][0], meshes, float(warp), camera,
                        RAMP_LEVELS if target.suffix.lower() == ".gif" else None, label)
    return _write_film(target, draw, fps, progress)


def _checked_target(path: str | os.PathLike[str], fps: float, warp: float) -> Path:
    """The animation's file, its suffix, ``fps`` and ``warp`` checked."""
    target = Path(path)
    suffix = target.suffix.lower()
    if suffix not in (".gif", ".mp4"):
        raise InputError(f"animations are written as .gif or .mp4, got {target.name!r}")
    if not (isinstance(fps, (int, float)) and np.isfinite(fps) and fps > 0):
        raise InputError(f"fps must be finite and > 0, got {fps!r}")
    if not (isinstance(warp, (int, float)) and np.isfinite(warp) and warp > 0):
        raise InputError(f"warp must be finite and > 0, got {warp!r}")
    if suffix == ".mp4" and not mp4_available():
        raise InputError("MP4 needs an ffmpeg encoder: install the extra `video` "
                         "(pip install 'splinedeform[video]') or write a .gif")
    return target


def _write_film(target: Path, draw: _FrameDrawer, fps: float, progress: Progress) -> Path:
    """Every frame of ``draw`` encoded into ``target`` (GIF or MP4, by the suffix)."""
    def frames() -> Iterator[NDArray[np.uint8]]:
        for f in range(len(draw)):
            yield cache.pop(f) if f in cache else draw(f)
            if progress is not None:
                progress(f + 1, len(draw))

    cache: dict[int, NDArray[np.uint8]] = {}
    if target.suffix.lower() == ".gif":
        return write_with(target, lambda tmp: _write_gif(tmp, draw, cache, frames(), fps))
    return write_with(target, lambda tmp: _write_mp4(tmp, frames(), fps))


def _write_gif(path: Path, draw: _FrameDrawer, cache: dict[int, NDArray[np.uint8]],
               frames: Iterator[NDArray[np.uint8]], fps: float) -> None:
    """The palette from the peak frame and :data:`PALETTE_SAMPLES` evenly spaced ones
    (drawn first and kept), then every frame mapped to it and written in order."""
    picks = np.unique(np.r_[np.linspace(0, len(draw) - 1, PALETTE_SAMPLES).round(), draw.peak])
    for f in picks.astype(int):
        cache[int(f)] = draw(int(f))
    palette = global_palette(np.stack(list(cache.values())), ramp_colors(COLORMAP, RAMP_LEVELS))
    to_palette = PaletteMap(palette)
    with open(path, "wb") as stream:
        writer = GifWriter(stream, ANIMATION_PIXELS, palette, 1000.0 / fps)
        for image in frames:
            writer.add(to_palette(image))
        writer.close()


def _write_mp4(path: Path, frames: Iterator[NDArray[np.uint8]], fps: float) -> None:
    import imageio.v2 as iio2

    writer = iio2.get_writer(path, format="FFMPEG", mode="I", fps=fps, codec="libx264",
                             quality=7, macro_block_size=16, ffmpeg_log_level="error")
    try:
        for image in frames:
            writer.append_data(image)
    finally:
        writer.close()
