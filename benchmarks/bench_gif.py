"""Cost of writing the animation's GIF: the palette of splinedeform.viz.gif against
imageio/pillow's adaptive per-frame quantisation (what ``write_animation`` did before).

The demo scenario (``splinedeform demo``: a half sphere, 32² tessellation) is solved once
and its motion sampled at ``--frames`` times (linear in time between the 41 computed
frames). Three timings, in one run:

* ``draw before``: every 640 × 480 frame drawn by a full redraw of the matplotlib figure
  (what ``write_animation`` did before);
* ``encode before``: ``imageio.v3.imwrite`` of the stacked frames (an adaptive palette per
  frame, all frames encoded at the end);
* ``after total``: ``write_animation`` (axes and colour bar drawn once, the surface drawn
  over them per frame; palette once from six sample frames, exact mapping, each frame
  encoded as it is drawn), and ``encode after``, that minus its own drawing time.

Run ``python benchmarks/bench_gif.py [--frames 301]``; report the load average beside it.
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time
from pathlib import Path

import numpy as np


def full_redraws(s, t, P):
    """The frames as drawn before: the surface swapped and the whole figure redrawn."""
    from splinedeform.viz.animation import ANIMATION_PIXELS
    from splinedeform.viz.figures import (DPI, _axes3d, _box, _collection, _colorbar,
                                          _face_colors, _figure)
    from splinedeform.viz.surfaces import _displaced_meshes

    X, mag, faces = _displaced_meshes(s, s.control_points, list(P), 32)
    vmax = float(mag.max())
    fig = _figure(ANIMATION_PIXELS[0] / DPI, ANIMATION_PIXELS[1] / DPI)
    ax = _axes3d(fig, [0.0, 0.02, 0.84, 0.9])
    _box(ax, X)
    _colorbar(fig, [0.86, 0.15, 0.025, 0.7], vmax)
    collection = None
    for f in range(len(t)):
        if collection is not None:
            collection.remove()
        collection = _collection(X[f], faces, _face_colors(mag[f], faces, vmax))
        ax.add_collection3d(collection)
        ax.set_title(f"t = {t[f]:.4g}", fontsize=11)
        fig.canvas.draw()
        yield np.asarray(fig.canvas.buffer_rgba())[..., :3].copy()


def main(frames: int) -> dict[str, float]:
    import imageio.v3 as iio

    from splinedeform import viz
    from splinedeform.cli import demo_scenario
    from splinedeform.pipeline import run
    from splinedeform.viz import animation

    from splinedeform.scenario import with_overrides

    result = run(with_overrides(demo_scenario(), {"output.formats": []}), None)
    s, times, nets = result.built.surface, result.times, result.nets
    t = np.linspace(times[0], times[-1], frames)
    i = np.clip(np.searchsorted(times, t) - 1, 0, len(times) - 2)
    a = ((t - times[i]) / (times[i + 1] - times[i]))[:, None, None, None]
    P = (1 - a) * nets[i] + a * nets[i + 1]
    drawn = {"seconds": 0.0}
    plain_call = animation._FrameDrawer.__call__

    def timed_call(self, f):           # the drawing time inside write_animation
        start = time.perf_counter()
        image = plain_call(self, f)
        drawn["seconds"] += time.perf_counter() - start
        return image

    with tempfile.TemporaryDirectory() as tmp:
        start = time.perf_counter()
        images = np.stack(list(full_redraws(s, t, P)))
        t_draw = time.perf_counter() - start
        start = time.perf_counter()
        iio.imwrite(Path(tmp) / "before.gif", images, extension=".gif", duration=1000 / 15,
                    loop=0)
        t_before = time.perf_counter() - start
        del images
        animation._FrameDrawer.__call__ = timed_call
        try:
            start = time.perf_counter()
            viz.write_animation(Path(tmp) / "after.gif", s, s.control_points, t, P, 32)
            t_after_total = time.perf_counter() - start
        finally:
            animation._FrameDrawer.__call__ = plain_call
        sizes = [os.path.getsize(Path(tmp) / name) for name in ("before.gif", "after.gif")]
    row = {"frames": frames, "draw before s": t_draw, "encode before s": t_before,
           "draw after s": drawn["seconds"], "after total s": t_after_total,
           "encode after s": t_after_total - drawn["seconds"],
           "encode ratio": t_before / max(t_after_total - drawn["seconds"], 1e-9),
           "before MB": sizes[0] / 1e6, "after MB": sizes[1] / 1e6,
           "load": os.getloadavg()[0]}
    print("  ".join(f"{k} {v:.3g}" if isinstance(v, float) else f"{k} {v}"
                    for k, v in row.items()))
    return row


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=41)
    main(parser.parse_args().frames)
