"""GIF encoding with one global palette that holds the colour bar's ramp exactly.

A GIF frame has at most 256 colours. The animation's palette is computed once, before the
first frame is written:

* the colour map sampled at :data:`RAMP_LEVELS` levels — the colour bar is drawn with
  exactly these colours, so every pixel of the bar is a palette entry and the bar shows a
  smooth ramp instead of the bands an adaptive per-frame palette cuts it into;
* :data:`GREY_LEVELS` greys from black to white (background, axes, text);
* the rest from the colours of a few sample frames (median cut of their non-grey pixels:
  the shaded surface).

Each pixel is mapped to its nearest palette entry in RGB (exact nearest neighbour, no
dithering: a pixel whose colour is in the palette keeps it), through a lookup table over
24-bit colours filled as new colours appear. Frames are written as they come
(:class:`GifWriter`), each cropped to the box where it differs from the previous one.
"""

from __future__ import annotations

import io
from typing import IO

import numpy as np
from numpy.typing import NDArray

#: colour-map levels held exactly by the palette (and drawn in the animation's colour bar)
RAMP_LEVELS = 128
#: evenly spaced greys from black to white
GREY_LEVELS = 16
PALETTE_SIZE = 256
#: at most this many sample pixels (every third, then evenly thinned) enter the median cut
FITTED_PIXELS = 60_000


def ramp_colors(colormap: str, levels: int = RAMP_LEVELS) -> NDArray[np.uint8]:
    """The colour map at ``levels`` evenly spaced values ``k / (levels - 1)``, as RGB bytes."""
    import matplotlib

    rgba = matplotlib.colormaps[colormap].resampled(levels)(np.arange(levels))
    return np.asarray(np.round(rgba[:, :3] * 255), dtype=np.uint8)


def global_palette(samples: NDArray[np.uint8], ramp: NDArray[np.uint8]) -> NDArray[np.uint8]:
    """The 256 × RGB palette: ``ramp``, :data:`GREY_LEVELS` greys, then the median cut (one
    k-means pass) of the non-grey pixels of ``samples (S, H, W, 3)`` (spread ``max - min``
    over the channels above 12; at most :data:`FITTED_PIXELS` of them) into the entries
    left."""
    from PIL import Image

    greys = np.repeat(np.round(np.linspace(0, 255, GREY_LEVELS)).astype(np.uint8)[:, None], 3, 1)
    left = PALETTE_SIZE - len(ramp) - GREY_LEVELS
    pixels = samples.reshape(-1, 3)[::3]
    colourful = pixels[np.ptp(pixels.astype(np.int16), axis=1) > 12]
    colourful = colourful[::-(-len(colourful) // FITTED_PIXELS) or 1]
    fitted = np.zeros((0, 3), dtype=np.uint8)
    if len(colourful) and left > 0:
        quantised = Image.fromarray(np.ascontiguousarray(colourful[None])).quantize(
            colors=left, method=Image.Quantize.MEDIANCUT, kmeans=1)
        used = len(np.unique(np.asarray(quantised)))
        fitted = np.asarray(quantised.getpalette()[:3 * used], dtype=np.uint8).reshape(-1, 3)
    palette = np.concatenate([ramp, greys, fitted])[:PALETTE_SIZE]
    pad = np.repeat(palette[-1:], PALETTE_SIZE - len(palette), axis=0)
    return np.concatenate([palette, pad])


class PaletteMap:
    """Nearest palette entry of every pixel: ``argmin_k |rgb - palette_k|``, exactly.

    A table over the 2²⁴ RGB colours (int16, 32 MB) remembers the entry of every colour
    met so far; only new colours are searched (k-d tree of the palette).
    """

    def __init__(self, palette: NDArray[np.uint8]) -> None:
        from scipy.spatial import cKDTree

        self.palette = np.asarray(palette, dtype=np.uint8)
        self._tree = cKDTree(self.palette.astype(float))
        self._table = np.full(1 << 24, -1, dtype=np.int16)

    def __call__(self, image: NDArray[np.uint8]) -> NDArray[np.uint8]:
        """Palette indices ``(H, W)`` of an RGB image ``(H, W, 3)``."""
        rgb = image.astype(np.uint32)
        codes = (rgb[..., 0] << 16) | (rgb[..., 1] << 8) | rgb[..., 2]
        index = self._table[codes]
        missing = index < 0
        if np.any(missing):
            new = np.unique(codes[missing])
            colours = np.stack([new >> 16, (new >> 8) & 255, new & 255], axis=-1)
            self._table[new] = self._tree.query(colours.astype(float))[1]
            index = self._table[codes]
        return index.astype(np.uint8)


class GifWriter:
    """A looping GIF89a written frame by frame with one global palette.

    ``add(indices)`` writes one frame of palette indices ``(H, W)`` (LZW by pillow),
    cropped to the box where it differs from the previous frame (the rest stays, disposal
    "do not dispose"); ``duration`` is in milliseconds, rounded to the hundredths GIF
    stores (at least 20 ms).
    """

    def __init__(self, stream: IO[bytes], size: tuple[int, int], palette: NDArray[np.uint8],
                 duration: float) -> None:
        width, height = size
        # GIF delays are whole hundredths of a second, at least 2 (viewers slow shorter ones)
        self.stream, self.size = stream, size
        self.duration = 10.0 * max(2, round(float(duration) / 10.0))
        self.palette = np.asarray(palette, dtype=np.uint8)
        self._previous: NDArray[np.uint8] | None = None
        # header, logical screen (global table of 2^(7+1) entries), NETSCAPE loop forever
        stream.write(b"GIF89a" + width.to_bytes(2, "little") + height.to_bytes(2, "little")
                     + bytes([0xF7, 0, 0]) + self.palette.tobytes())
        stream.write(b"!\xff\x0bNETSCAPE2.0\x03\x01\x00\x00\x00")

    def add(self, indices: NDArray[np.uint8]) -> None:
        from PIL import GifImagePlugin, Image

        if indices.shape != self.size[::-1]:
            raise ValueError(f"frame of shape {indices.shape}, expected {self.size[::-1]}")
        box = (0, 0, *self.size)
        if self._previous is not None:
            changed = indices != self._previous
            rows, cols = np.flatnonzero(changed.any(axis=1)), np.flatnonzero(changed.any(axis=0))
            box = (int(cols[0]), int(rows[0]), int(cols[-1]) + 1, int(rows[-1]) + 1) \
                if rows.size else (0, 0, 1, 1)
        self._previous = indices
        frame = Image.fromarray(np.ascontiguousarray(indices[box[1]:box[3], box[0]:box[2]]), "P")
        frame.putpalette(self.palette.tobytes())
        data = io.BytesIO()
        for chunk in GifImagePlugin.getdata(frame, offset=box[:2], duration=self.duration):
            data.write(chunk)
        self.stream.write(data.getvalue())
        self.stream.flush()

    def close(self) -> None:
        self.stream.write(b";")
