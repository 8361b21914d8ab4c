"""The warp factor, camera and frame rate of the pictures and the animation.

References: the rule ``w = nice(0.2 size / max |d|)`` worked by hand; the drawn vertices
``x_rest + w d`` against the surface evaluated point by point; the scenario keys against
their stated bounds.
"""

from __future__ import annotations

import numpy as np
import pytest

from splinedeform import BSplineBasis, InputError, ScenarioError, Surface, viz
from splinedeform.outputs import picture_warp
from splinedeform.pipeline import run
from splinedeform.scenario import parse_scenario
from splinedeform.viz.surfaces import _displaced_meshes
from splinedeform.viz.warp import auto_warp, warp_caption

from tiny_scenario import BASE


@pytest.mark.parametrize("largest, size, expected", [
    (0.002, 1.0, 100.0),     # 0.2 / 0.002 = 100 exactly
    (0.004, 1.0, 50.0),      # 50 exactly
    (0.0041, 1.0, 50.0),     # 48.8: nearer 50 than 20 in ratio
    (0.003, 2.0, 100.0),     # 133: 100 (ratio 1.33) rather than 200 (1.5)
    (0.0006, 1.0, 500.0),    # 333: 500 (ratio 1.5) rather than 200 (1.67)
    (0.5, 1.0, 1.0),         # already large: never shrunk
    (0.05, 1.0, 1.0),        # 5 % of the size is visible as it is
    (0.0499, 2.0, 10.0),     # 2.5 %: 8.02 -> 10
    (0.0, 1.0, 1.0),         # no motion
])
def test_auto_warp_takes_the_nearest_of_one_two_five(largest, size, expected):
    assert auto_warp(largest, size) == expected        # nice numbers: exact
    assert warp_caption(1.0) == ""
    assert "× 50" in warp_caption(50.0)


def test_auto_warp_rejects_nonsense():
    with pytest.raises(InputError, match="warp"):
        auto_warp(float("nan"), 1.0)
    with pytest.raises(InputError, match="warp"):
        auto_warp(-1.0, 1.0)


def test_the_drawn_surface_is_the_rest_plus_warp_times_displacement():
    b = BSplineBasis(2, 2, 1.0, "open")
    gu, gv = np.meshgrid(b.greville(), b.greville(), indexing="ij")
    s = Surface(np.stack([gu, gv, 0 * gu], -1), b, b)
    moved = s.control_points.copy()
    moved[1:-1, 1:-1, 2] = 0.01
    X, mag, _ = _displaced_meshes(s, s.control_points, [moved], 5, warp=30.0)
    u, v = s.sample_parameters(5)
    uu, vv = np.meshgrid(u, v, indexing="ij")
    true_z = s.with_control_points(moved).evaluate(uu, vv)[..., 2].ravel()
    # welding keeps every vertex of an open plane; 1e-12: rounding of a sum of 9 products
    np.testing.assert_allclose(X[0, :, 2], 30.0 * true_z, atol=1e-12)
    np.testing.assert_allclose(mag[0], np.abs(true_z), atol=1e-12)   # colours: true |d|


def test_render_surfaces_refuses_a_bad_warp(tmp_path):
    b = BSplineBasis(2, 2, 1.0, "open")
    s = Surface(np.zeros((4, 4, 3)) + np.arange(4)[:, None, None], b, b)
    with pytest.raises(InputError, match="warp"):
        viz.render_surfaces(tmp_path / "s.png", s, s.control_points, [s.control_points],
                            ["a"], warp=-2.0)


def scenario(output: str):
    return parse_scenario(BASE.replace('formats = []', output), source="tiny.toml")


def test_a_run_draws_with_the_automatic_warp_camera_and_fps(monkeypatch, tmp_path):
    drawn: dict = {}

    def capture(name):
        def fake(path, *args, **kwargs):
            drawn[name] = kwargs
            path.write_bytes(b"")
            return path
        return fake

    monkeypatch.setattr(viz, "render_surfaces", capture("picture"))
    monkeypatch.setattr(viz, "write_animation", capture("animation"))
    monkeypatch.setattr(viz, "plot_probes", lambda path, *a, **k: path.write_bytes(b"") or path)
    result = run(scenario('formats = ["images", "gif"]\ncamera = [45, 10]\nfps = 8'), tmp_path)
    size = float(np.ptp(result.rest_net.reshape(-1, 3), axis=0).max())
    raw = 0.2 * size / result.max_displacement
    nice = [m * 10.0 ** k for k in range(-3, 8) for m in (1, 2, 5)]
    expected = max(1.0, min(nice, key=lambda n: abs(np.log(n / raw))))
    if result.max_displacement >= 0.05 * size:
        expected = 1.0
    assert picture_warp(result) == expected
    for name in ("picture", "animation"):
        assert drawn[name]["warp"] == expected and drawn[name]["camera"] == (45.0, 10.0)
    assert drawn["animation"]["fps"] == 8.0
    fixed = run(scenario('formats = []\nwarp = 3.5'), None)
    assert picture_warp(fixed) == 3.5


@pytest.mark.parametrize("line, where", [
    ('warp = "big"', "output.warp"), ("warp = 0", "output.warp"),
    ("camera = [10]", "output.camera"), ("fps = 0", "output.fps"), ("fps = 120", "output.fps"),
    ("animate_modes = [1]", "output.animate_modes"),     # a dynamic solve has no mode frames
])
def test_bad_output_view_keys_are_located(line, where):
    with pytest.raises(ScenarioError, match=where):
        scenario(f"formats = []\n{line}")


def test_the_warp_factor_is_stated_in_the_picture_and_the_animation():
    from splinedeform.viz.animation import _FrameDrawer
    from splinedeform.viz.surfaces import surfaces_figure

    b = BSplineBasis(2, 2, 1.0, "open")
    gu, gv = np.meshgrid(b.greville(), b.greville(), indexing="ij")
    s = Surface(np.stack([gu, gv, 0 * gu], -1), b, b)
    moved = s.control_points.copy()
    moved[1:-1, 1:-1, 2] = 0.004
    X, mag, faces = _displaced_meshes(s, s.control_points, [s.control_points, moved], 4, 50.0)
    texts = lambda fig: " ".join(t.get_text() for t in fig.texts)   # noqa: E731
    assert "× 50" in texts(surfaces_figure(X, mag, faces, ["a", "b"], float(mag.max()),
                                           warp=50.0))
    assert "×" not in texts(surfaces_figure(X, mag, faces, ["a", "b"], float(mag.max())))
    draw = _FrameDrawer(np.array([0.0, 1.0]), (X, mag, faces), 50.0, (20.0, 30.0),
                        label="load factor")
    draw(1)
    assert draw.ax.get_title() == "load factor = 1  ·  displacement drawn × 50 (output.warp)"
    assert (draw.ax.elev, draw.ax.azim) == (20.0, 30.0)
