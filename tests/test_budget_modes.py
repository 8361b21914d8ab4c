"""The budget of a modes solve's per-mode files, and of animations written frame by frame."""
from __future__ import annotations

import pytest

from splinedeform import ScenarioError
from splinedeform.budget import estimate
from splinedeform.budget_outputs import ANIMATION_HELD_FRAMES, animation_memory
from splinedeform.pipeline import run
from splinedeform.scenario import build, parse_scenario

DRUM = """\
[surface]
shape = "plane"
cells = {cells}

[material]
w10 = 1.0
w01 = 1.0

[boundary]
u0 = "pinned"
u1 = "pinned"
v0 = "pinned"
v1 = "pinned"

[solve]
kind = "modes"
modes = {modes}
frames = {frames}

[output]
formats = {formats}
resolution = 6
animate_modes = {animated}
"""


def drum(formats: str, modes: int = 3, frames: int = 5, animated: str = "[1, 3]",
         cells: int = 4):
    return parse_scenario(DRUM.format(formats=formats, modes=modes, frames=frames,
                                      animated=animated, cells=cells), source="drum.toml")


def test_the_per_mode_files_are_counted_and_bound_what_is_written(tmp_path):
    # 3 modes: <name>_modes.vtu, 3 x (json, npz) mode nets, mode 3's GIF and its series of
    # 5 frames + .pvd, besides the run's 5 frames + .pvd, its nets and its GIF:
    # 5 + 1 + 2 + 1 + 1 + 6 + 1 + 6 = 23 files, counted exactly (the manifest is the run's
    # own, one more)
    s = drum('["vtu", "json", "npz", "gif"]')
    found = estimate(s, build(s).model)
    mode_files = sum(t.amount for t in found.files if "mode" in t.formula)
    assert mode_files == 1 + 3 * 2 + 1 + 6
    assert found.total("files") == 23
    out = tmp_path / "out"
    run(s, out)
    written = list(out.iterdir())
    assert found.total("files") <= len(written) <= found.total("files") + 1
    # disk is an upper bound by construction (uncompressed sizes; 1 MiB for the manifest
    # and file-system rounding)
    assert sum(p.stat().st_size for p in written) <= found.total("disk") + 2**20


def test_a_modes_solve_with_many_animated_modes_is_refused_naming_them(tmp_path):
    # 199 animated modes besides mode 1, 300 frames each: 199 x 300 x (1.5e8 + 1.5e4 · 36
    # + 1e7 + 2 · 36 · 16 · 3) = 9.6e12 operations against the 1e12 of the default budget
    animated = "[" + ", ".join(str(k) for k in range(1, 201)) + "]"
    s = drum('["gif"]', modes=200, frames=300, animated=animated, cells=16)
    found = estimate(s, build(s).model)
    films = next(t for t in found.work if t.formula.startswith("199 mode animation(s)"))
    assert films.amount == pytest.approx(199 * 300 * (1.5e8 + 1.5e4 * 36 + 1e7 + 6 * 36 * 16),
                                         rel=1e-12)      # exact sum of the stated terms
    with pytest.raises(ScenarioError) as info:
        run(s, tmp_path / "out")
    message = str(info.value)
    assert "output.animate_modes: this run exceeds its budget" in message
    assert "199 mode animation(s) of 300 frames (gif)" in message
    assert not (tmp_path / "out").exists() or not any((tmp_path / "out").iterdir())


def test_many_modes_with_nets_are_counted_per_mode():
    # K mode nets of F G 3 numbers: 200 modes x 40 frames x 19² points x 3 x 25 bytes of
    # JSON = 217 MB, 200 files (the run's own nets are one more file, counted apart)
    s = drum('["json"]', modes=200, frames=40, animated="[1]", cells=16)
    found = estimate(s, build(s).model)
    nets = next(t for t in found.disk if t.formula.startswith("200 mode nets .json"))
    assert nets.amount == pytest.approx(200 * 40 * 19**2 * 3 * 25.0, rel=1e-12)   # exact
    assert found.total("files") == 200 + 1


def test_the_animation_memory_no_longer_grows_with_the_frames():
    # the GIF is written frame by frame: the palette's 6 sample images (twice), the canvas
    # and its background, the 2²⁴ x 2-byte lookup table and 8 MiB for matplotlib's figure,
    # whatever the frame count
    from splinedeform.viz.animation import PALETTE_SAMPLES

    assert ANIMATION_HELD_FRAMES == PALETTE_SAMPLES + 1          # the samples and the peak
    held = 2 * 6 * 640 * 480 * 3 + 2 * 640 * 480 * 4 + 2**25 + 2**23
    assert animation_memory(300) == animation_memory(10**5) == held
    assert animation_memory(2) == held - 2 * 4 * 640 * 480 * 3


def test_writing_a_gif_holds_no_more_images_than_the_estimate_counts(tmp_path, monkeypatch):
    # a 20-frame GIF: the frames drawn ahead for the palette are kept (and stacked once for
    # the median cut) until written, every other frame is drawn, mapped and written alone;
    # the stack is the most held at once: at most ANIMATION_HELD_FRAMES of 640 x 480 x 3
    # bytes (the peak frame and 5 evenly spaced), whatever the frame count
    import numpy as np

    from splinedeform import shapes
    from splinedeform.viz import animation

    stacked: list[tuple[int, ...]] = []
    fit = animation.global_palette

    def recording_palette(samples, ramp):
        stacked.append(samples.shape)
        return fit(samples, ramp)

    monkeypatch.setattr(animation, "global_palette", recording_palette)
    surface = shapes.plane(size=(1.0, 1.0), cells=(3, 3), degree=3)
    rest = surface.control_points
    times = np.linspace(0.0, 1.0, 20)
    nets = rest + np.sin(2 * np.pi * times)[:, None, None, None] * 0.1 * np.ones_like(rest)
    animation.write_animation(tmp_path / "film.gif", surface, rest, times, nets, resolution=6)
    assert len(stacked) == 1 and 1 <= stacked[0][0] <= ANIMATION_HELD_FRAMES
    assert stacked[0][1:] == (480, 640, 3)
    # the estimate counts them twice (kept and stacked), besides the lookup table
    assert animation_memory(20) >= 2 * ANIMATION_HELD_FRAMES * 640 * 480 * 3 + 2**25
