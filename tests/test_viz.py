"""Pictures and animations: sizes, content, the colour scale, the PyVista fallback."""

from __future__ import annotations

import base64
import warnings

import numpy as np
import pytest

from splinedeform import BSplineBasis, InputError, Surface
from splinedeform import viz

matplotlib = pytest.importorskip("matplotlib")
iio = pytest.importorskip("imageio.v3")


def plane(cells: int = 4) -> Surface:
    """The unit square z = 0 with open cubic knots (control points at Greville abscissae)."""
    b = BSplineBasis(3, cells, 1.0, "open")
    gu, gv = np.meshgrid(b.greville(), b.greville(), indexing="ij")
    return Surface(np.stack([gu, gv, 0 * gu], -1), b, b, name="plane")


def bump(surface: Surface) -> np.ndarray:
    """A control-net bump field that vanishes on the boundary rows."""
    g = surface.control_points
    return np.sin(np.pi * g[..., 0]) * np.sin(np.pi * g[..., 1])


def motion(surface: Surface, frames: int = 5) -> tuple[np.ndarray, np.ndarray]:
    times = np.linspace(0.0, 1.0, frames)
    lift = np.zeros_like(surface.control_points)
    lift[..., 2] = 0.4 * bump(surface)
    return times, surface.control_points[None] + np.sin(np.pi * times / 2)[:, None, None, None] * lift


def read_png(path) -> np.ndarray:
    image = iio.imread(path)
    return image[..., :3].astype(int)


def distinct_colours(image: np.ndarray) -> int:
    return len(np.unique(image.reshape(-1, 3), axis=0))


def luminance(rgb: np.ndarray) -> np.ndarray:
    return rgb @ np.array([0.2126, 0.7152, 0.0722])


# -- colour scale ------------------------------------------------------------------------
def test_displacement_colours_are_monotone_from_cool_to_hot():
    m = np.linspace(0.0, 2.0, 50)
    rgba = viz.displacement_colors(m, vmax=2.0)
    cmap = matplotlib.colormaps[viz.COLORMAP]
    np.testing.assert_allclose(rgba[0], cmap(0.0))
    np.testing.assert_allclose(rgba[-1], cmap(1.0))
    # plasma: lightness rises monotonically, and the hot end is bright yellow
    assert np.all(np.diff(luminance(rgba[:, :3])) > 0)
    assert rgba[-1, 0] > 0.9 and rgba[-1, 2] < 0.2 and rgba[0, 2] > 0.5


def test_larger_displacement_gets_the_hot_end():
    small, large = viz.displacement_colors(np.array([0.1, 0.9]))   # vmax = 0.9
    np.testing.assert_allclose(large, matplotlib.colormaps[viz.COLORMAP](1.0))
    assert luminance(large[:3]) > luminance(small[:3])
    # values above vmax saturate at the hot end, and vmax = 0 gives the cool end
    np.testing.assert_allclose(viz.displacement_colors([5.0], vmax=1.0)[0], large)
    np.testing.assert_allclose(viz.displacement_colors([0.0, 0.0])[1],
                               matplotlib.colormaps[viz.COLORMAP](0.0))


def test_displacement_colours_reject_bad_values():
    with pytest.raises(InputError, match=">= 0"):
        viz.displacement_colors([-1.0])
    with pytest.raises(InputError, match="finite"):
        viz.displacement_colors([np.nan])


def test_shading_follows_lambert():
    rgba = np.array([[1.0, 0.5, 0.2, 1.0]] * 2)
    normals = np.array([viz.LIGHT, [viz.LIGHT[1], -viz.LIGHT[0], 0.0]])   # along / across light
    shaded = viz.shade(rgba, normals * 3.0)
    np.testing.assert_allclose(shaded[0, :3], rgba[0, :3])
    np.testing.assert_allclose(shaded[1, :3], 0.55 * rgba[1, :3])
    assert np.all(shaded[:, 3] == 1.0)


# -- render_surfaces ----------------------------------------------------------------------------
def hot_pixels(image: np.ndarray) -> int:
    """Pixels near plasma's yellow end (allowing for the shading factor 0.55..1)."""
    r, g, b = image[..., 0], image[..., 1], image[..., 2]
    return int(np.sum((r > 130) & (g > 100) & (b < 70) & (r > 1.1 * g)))


def test_render_surfaces_size_and_hot_region(tmp_path, monkeypatch):
    monkeypatch.setattr(viz.surfaces, "_pyvista", lambda: None)
    s = plane()
    _, nets = motion(s)
    path = viz.render_surfaces(tmp_path / "initial_final.png", s, s.control_points,
                               [nets[0], nets[-1]], ["initial", "final"], resolution=24)
    image = read_png(path)
    assert image.shape == (400, 2 * 400 + 150, 3)
    assert distinct_colours(image) > 200
    # the rest state has no displacement: no hot pixel; the bumped state has a hot top
    assert hot_pixels(image[:, :400]) == 0
    assert hot_pixels(image[:, 400:800]) > 200


def test_render_surfaces_falls_back_to_matplotlib_silently(tmp_path, monkeypatch, capsys):
    class BrokenPyVista:
        """Importable, but it cannot open an off-screen context."""

        @staticmethod
        def Plotter(*args, **kwargs):
            raise RuntimeError("cannot open display")

    monkeypatch.setattr(viz.surfaces, "_pyvista", lambda: BrokenPyVista)
    s = plane(3)
    _, nets = motion(s, 2)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        path = viz.render_surfaces(tmp_path / "r.png", s, s.control_points, [nets[-1]], ["t=1"],
                                   resolution=12)
    assert read_png(path).shape == (400, 550, 3)
    assert capsys.readouterr() == ("", "")
    assert [p.name for p in tmp_path.iterdir()] == ["r.png"]


def test_render_surfaces_uses_pyvista_when_it_can_render(tmp_path, monkeypatch):
    """A stand-in for PyVista records the calls; its screenshot becomes the target file."""
    calls: list[str] = []

    class FakePlotter:
        def __init__(self, off_screen, shape, window_size, border):
            assert off_screen and shape == (1, 2) and window_size == (950, 400)
            calls.append("open")

        def subplot(self, row, col):
            calls.append(f"panel {col}")

        def add_mesh(self, mesh, scalars, cmap, clim, show_scalar_bar):
            assert cmap == viz.COLORMAP and clim[0] == 0.0
            assert (mesh.point_data[scalars] >= 0).all()     # lengths of displacements

        def add_text(self, text, font_size):
            calls.append(text)

        def view_isometric(self):
            pass

        def link_views(self):
            pass

        def screenshot(self, filename):
            iio.imwrite(filename, np.full((400, 950, 3), 200, np.uint8), extension=".png")

        def close(self):
            calls.append("close")

    class FakeMesh:
        def __init__(self, points, cells):
            assert cells.reshape(-1, 4)[:, 0].tolist() == [3] * (cells.size // 4)
            self.point_data: dict = {}

    class FakePyVista:
        Plotter = FakePlotter
        PolyData = FakeMesh

    monkeypatch.setattr(viz.surfaces, "_pyvista", lambda: FakePyVista)
    s = plane(3)
    _, nets = motion(s, 2)
    path = viz.render_surfaces(tmp_path / "r.png", s, s.control_points, list(nets), ["a", "b"],
                               resolution=8)
    assert calls == ["open", "panel 0", "a", "panel 1", "b", "close"]
    assert np.all(read_png(path) == 200)


def test_render_surfaces_rejects_bad_input(tmp_path):
    s = plane(3)
    with pytest.raises(InputError, match="title"):
        viz.render_surfaces(tmp_path / "r.png", s, s.control_points, [s.control_points], [])
    with pytest.raises(InputError, match="PNG"):
        viz.render_surfaces(tmp_path / "r.jpg", s, s.control_points, [s.control_points], ["a"])
    with pytest.raises(InputError, match=r"nets\[0\]"):
        viz.render_surfaces(tmp_path / "r.png", s, s.control_points, [np.zeros((2, 2, 3))], ["a"])
    assert list(tmp_path.iterdir()) == []


# -- probes and modes -------------------------------------------------------------------------
def test_plot_probes_size_and_content(tmp_path):
    t = np.linspace(0, 2, 40)
    d = np.column_stack([np.sin(t), 0 * t, -np.cos(t)])
    path = viz.plot_probes(tmp_path / "probes.png", t, {"centre": d, "edge": 0.5 * d})
    image = read_png(path)
    assert image.shape == (500, 800, 3)
    assert distinct_colours(image) > 20
    with pytest.raises(InputError, match="probe 'edge'"):
        viz.plot_probes(tmp_path / "p.png", t, {"edge": d[:, :2]})
    with pytest.raises(InputError, match="non-empty"):
        viz.plot_probes(tmp_path / "p.png", t, {})


def test_mode_geometry_displaces_along_the_normal():
    s = plane(4)
    phi = bump(s) - 0.2
    y, values, faces = viz.mode_geometry(s, phi, resolution=9, scale=0.2)
    u = np.linspace(0, 1, 9)
    uu, vv = np.meshgrid(u, u, indexing="ij")
    expected = s.with_control_points(np.repeat(phi[..., None], 3, -1)).evaluate(uu, vv)[..., 0]
    np.testing.assert_allclose(values, expected.ravel(), atol=1e-14)
    # plane z = 0 with normal +z: x, y unchanged, z = s φ with s = 0.2 · diameter / max|φ|
    np.testing.assert_allclose(y[:, :2], s.evaluate(uu, vv)[..., :2].reshape(-1, 2), atol=1e-14)
    np.testing.assert_allclose(y[:, 2], 0.2 * 1.0 * values / np.abs(values).max(), atol=1e-14)
    assert faces.shape == (2 * 8 * 8, 3)


def test_plot_modes_size_and_checks(tmp_path):
    s = plane(4)
    shapes = np.stack([bump(s), bump(s) * (s.control_points[..., 0] - 0.5)])
    path = viz.plot_modes(tmp_path / "modes.png", s, [3.2, 7.9], shapes, resolution=16)
    image = read_png(path)
    # two 320 px panels and a 110 px bar column, white margins trimmed
    assert image.shape[0] <= 320 and image.shape[1] <= 750
    assert distinct_colours(image) > 100
    ink = np.any(image < 250, axis=-1)
    rows, cols = np.flatnonzero(ink.any(axis=1)), np.flatnonzero(ink.any(axis=0))
    margin = viz.figures.MARGIN_PIXELS
    assert rows[0] <= margin and cols[0] <= margin                   # no wide white border
    assert rows[-1] >= image.shape[0] - 1 - margin and cols[-1] >= image.shape[1] - 1 - margin
    # the colour bar, right of the panels, spans the diverging map: deep red (coolwarm(1)
    # is (180, 4, 38)) at the top, deep blue ((59, 76, 192) at 0) at the bottom
    bar = image[:, -image.shape[1] // 6:]
    red = np.nonzero(bar[..., 0] - bar[..., 2] > 120)[0]
    blue = np.nonzero(bar[..., 2] - bar[..., 0] > 120)[0]
    assert red.size > 100 and blue.size > 100 and red.mean() < blue.mean()
    with pytest.raises(InputError, match="shapes"):
        viz.plot_modes(tmp_path / "m.png", s, [1.0], shapes)


# -- animation ----------------------------------------------------------------------------------
def test_gif_has_one_distinct_frame_per_time(tmp_path):
    s = plane(3)
    times, nets = motion(s, 4)
    calls = []
    path = viz.write_animation(tmp_path / "motion.gif", s, s.control_points, times, nets,
                               resolution=10, progress=lambda done, total: calls.append((done, total)))
    frames = iio.imread(path, index=None)
    assert frames.shape[:3] == (4, 480, 640)
    for a, b in zip(frames[:-1], frames[1:]):
        assert np.mean(np.any(a != b, axis=-1)) > 0.005
    assert calls == [(1, 4), (2, 4), (3, 4), (4, 4)]
    assert [p.name for p in tmp_path.iterdir()] == ["motion.gif"]


def test_gif_progress_counts_frames_already_encoded(tmp_path):
    """Each progress call finds the (temporary) GIF longer: frames are encoded as they are
    drawn, not all at the end after the last count."""
    s = plane(3)
    times, nets = motion(s, 4)
    sizes = []

    def progress(done, total):
        sizes.append(sum(p.stat().st_size for p in tmp_path.iterdir()))

    viz.write_animation(tmp_path / "motion.gif", s, s.control_points, times, nets,
                        resolution=8, progress=progress)
    assert len(sizes) == 4 and sizes[0] > 768            # header and 256-colour table
    assert all(b > a for a, b in zip(sizes, sizes[1:]))


def test_a_frame_drawn_over_the_kept_background_is_the_full_drawing():
    """Only the surface and the title are drawn per frame; a full redraw of the figure
    with the same surface gives the same picture (8 levels of 255 and 0.5 % of the
    pixels: antialiasing along the silhouette, composited once more over the background)."""
    from splinedeform.viz.animation import _FrameDrawer
    from splinedeform.viz.figures import _collection, _face_colors
    from splinedeform.viz.surfaces import _displaced_meshes

    s = plane(3)
    times, nets = motion(s, 3)
    draw = _FrameDrawer(np.asarray(times, dtype=float),
                        _displaced_meshes(s, s.control_points, list(nets), 10, 1.0), 1.0,
                        (28.0, -60.0))
    draw(0)
    image = draw(2)
    surface = _collection(draw.X[2], draw.faces, _face_colors(draw.mag[2], draw.faces,
                                                              draw.vmax))
    draw.ax.add_collection3d(surface)
    draw.fig.canvas.draw()
    full = np.asarray(draw.fig.canvas.buffer_rgba())[..., :3].astype(int)
    assert np.mean(np.any(np.abs(full - image) > 8, axis=-1)) < 0.005
    assert np.mean(np.any(image != draw(0), axis=-1)) > 0.01     # frames do differ


def test_gif_colour_bar_is_the_colour_map_ramp_exactly(tmp_path):
    """Every pixel down the middle of the bar is one of the ramp's colours, unchanged by the
    palette, and the bar climbs the ramp level by level (no bands of one colour)."""
    from splinedeform.viz.gif import RAMP_LEVELS, ramp_colors

    s = plane(3)
    times, nets = motion(s, 3)
    path = viz.write_animation(tmp_path / "motion.gif", s, s.control_points, times, nets,
                               resolution=10)
    frame = iio.imread(path, index=1)[..., :3].astype(int)
    # the bar's axes span x in [0.86, 0.885] and y in [0.15, 0.85] of the 640 x 480 frame
    column = frame[480 - int(0.85 * 480) + 3:480 - int(0.15 * 480) - 3, int(0.8725 * 640)]
    ramp = ramp_colors(viz.COLORMAP).astype(int)
    match = np.all(column[:, None, :] == ramp[None], axis=-1)
    assert match.any(axis=1).all()              # exact: every bar pixel is a ramp colour
    level = match.argmax(axis=1)[::-1]          # bottom (0) to top (RAMP_LEVELS - 1)
    assert np.all(np.diff(level) >= 0)
    # 330 rows for 128 levels: all but a few levels at the two ends appear
    assert len(np.unique(level)) >= RAMP_LEVELS - 4


def test_gif_palette_maps_to_the_nearest_entry():
    """The lookup table agrees with a brute-force nearest search over the palette."""
    from splinedeform.viz.gif import PaletteMap

    rng = np.random.default_rng(3)
    palette = rng.integers(0, 256, (256, 3)).astype(np.uint8)
    image = rng.integers(0, 256, (40, 50, 3)).astype(np.uint8)
    image[0, :5] = palette[[7, 8, 9, 200, 255]]        # palette colours map to themselves
    index = PaletteMap(palette)(image)
    distance = ((image[..., None, :].astype(int) - palette.astype(int)) ** 2).sum(-1)
    chosen = np.take_along_axis(distance, index[..., None].astype(int), -1)[..., 0]
    # squared distances of 8-bit colours are integers: a colour that is not the nearest is
    # off by at least 1, so half of that separates a right choice from a wrong one
    np.testing.assert_allclose(chosen, distance.min(-1), rtol=0, atol=0.5)
    assert index[0, :5].tolist() == [7, 8, 9, 200, 255]


def test_gif_frame_delay_follows_fps(tmp_path):
    s = plane(3)
    times, nets = motion(s, 2)
    path = viz.write_animation(tmp_path / "m.gif", s, s.control_points, times, nets,
                               resolution=6, fps=25.0)
    from PIL import Image

    with Image.open(path) as gif:
        # the frame delay stored in the file's header (no time is measured): 1000 / 25 ms
        delay_ms = gif.info["duration"]            # an integer of the header, not a timing
        assert gif.n_frames == 2 and delay_ms == round(1000 / 25)
        assert gif.info["loop"] == 0


def test_mp4_when_an_encoder_is_available(tmp_path):
    if not viz.mp4_available():
        pytest.skip("imageio-ffmpeg (the `video` extra) is not installed")
    s = plane(3)
    times, nets = motion(s, 6)
    path = viz.write_animation(tmp_path / "motion.mp4", s, s.control_points, times, nets,
                               resolution=10)
    frames = iio.imread(path, index=None, plugin="FFMPEG")
    assert frames.shape[:3] == (6, 480, 640)
    assert np.abs(frames[0].astype(int) - frames[-1].astype(int)).mean() > 0.5


def test_mp4_without_encoder_names_the_extra(tmp_path, monkeypatch):
    monkeypatch.setattr(viz.animation, "mp4_available", lambda: False)
    s = plane(3)
    times, nets = motion(s, 2)
    with pytest.raises(InputError, match="video"):
        viz.write_animation(tmp_path / "m.mp4", s, s.control_points, times, nets)
    with pytest.raises(InputError, match=".gif or .mp4"):
        viz.write_animation(tmp_path / "m.avi", s, s.control_points, times, nets)
    assert list(tmp_path.iterdir()) == []


# -- viewer data -----------------------------------------------------------------------------------
def test_viewer_data_holds_float32_frames_and_nets():
    s = plane(3)
    times, nets = motion(s, 3)
    data = viz.viewer_data(s, s.control_points, times, nets, resolution=7)
    frames = np.frombuffer(base64.b64decode(data["frames"]), "<f4").reshape(3, 49, 3)
    for f in range(3):
        V, F = s.tessellate(7, control_points=nets[f])
        # the page's frames are float32 of a tessellation made by another path (all frames
        # at once): equal to one float32 rounding, 2⁻²³ ≈ 1.2e-7 of the size, with margin
        size = float(np.abs(V).max())
        np.testing.assert_allclose(frames[f], V, rtol=0, atol=4e-7 * size)
    faces = np.frombuffer(base64.b64decode(data["faces"]), "<u4").reshape(-1, 3)
    # vertex indices are integers: a wrong index is off by at least 1
    np.testing.assert_allclose(faces, F, rtol=0, atol=0.5)
    # the nets are sent as float32: one rounding, 2⁻²⁴ of each value
    np.testing.assert_allclose(np.frombuffer(base64.b64decode(data["nets"]), "<f4"),
                               nets.ravel(), rtol=6e-8, atol=1e-30)
    rest, _ = s.tessellate(7)
    top = max(np.linalg.norm(s.tessellate(7, control_points=n)[0] - rest, axis=1).max()
              for n in nets)
    assert data["vmax"] == pytest.approx(top, rel=1e-12)
    assert data["times"] == times.tolist() and data["netShape"] == [6, 6]
    assert data["startFrame"] == 2            # sin(πt/2) rises to the last frame


def test_viewer_starts_at_the_peak_not_the_last_frame():
    s = plane(3)
    times = np.linspace(0.0, 1.0, 7)
    lift = np.zeros_like(s.control_points)
    lift[..., 2] = 0.3 * bump(s)
    nets = s.control_points[None] + np.sin(np.pi * times)[:, None, None, None] * lift
    # sin(πt) on 7 frames peaks at t = 1/2, frame 3, and is back to rest at the end
    assert viz.viewer_data(s, s.control_points, times, nets, resolution=5)["startFrame"] == 3


def test_vertex_checksum_weights():
    x = np.array([[1.0, 2.0, 3.0], [4.0, 5.0, 6.0], [7.0, 8.0, 9.0]])
    w = np.array([1, 2, 3, 4, 5, 6, 7, 1, 2])
    assert viz.vertex_checksum(x) == float(np.sum(w * x.ravel()))
