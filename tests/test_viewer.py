"""viewer.html in a real browser: headless Chromium driven by Playwright.

The page must draw the surface with WebGL offline (no request leaves file://), log no
error, and redraw the geometry of the chosen frame when the time slider moves: the
drawn vertex positions (through the page's test hook) must equal the frame's mesh
computed here, and the screenshot must change.
"""

from __future__ import annotations

import io
import re
from pathlib import Path

import numpy as np
import pytest

from splinedeform import BSplineBasis, InputError, Surface
from splinedeform import viz

# skips this module, saying why, without Chromium or Playwright
import chromium  # noqa: E402,F401

RESOLUTION = 20
Image = pytest.importorskip("PIL.Image")


def deforming_plate() -> tuple[Surface, np.ndarray, np.ndarray]:
    """A unit plate whose middle rises and falls back: z = 0.5 sin(πt) · bump."""
    b = BSplineBasis(3, 4, 1.0, "open")
    gu, gv = np.meshgrid(b.greville(), b.greville(), indexing="ij")
    surface = Surface(np.stack([gu, gv, 0 * gu], -1), b, b, name="rising plate")
    times = np.linspace(0.0, 1.0, 9)
    lift = np.zeros_like(surface.control_points)
    lift[..., 2] = 0.5 * np.sin(np.pi * gu) * np.sin(np.pi * gv)
    nets = surface.control_points[None] + np.sin(np.pi * times)[:, None, None, None] * lift[None]
    return surface, times, nets


@pytest.fixture(scope="module")
def viewer_file(tmp_path_factory) -> tuple[Path, Surface, np.ndarray]:
    surface, times, nets = deforming_plate()
    path = viz.write_viewer(tmp_path_factory.mktemp("viewer") / "viewer.html", surface,
                            surface.control_points, times, nets, resolution=RESOLUTION)
    return path, surface, nets


@pytest.fixture
def page(browser, viewer_file):
    context = browser.new_context(viewport={"width": 900, "height": 600})
    pg = context.new_page()
    problems: list[str] = []
    requests: list[str] = []
    pg.on("console", lambda m: problems.append(m.text) if m.type == "error" else None)
    pg.on("pageerror", lambda e: problems.append(f"uncaught: {e}"))
    pg.on("request", lambda r: requests.append(r.url))
    pg.goto(viewer_file[0].as_uri())
    # predicates as functions: an expression string would be compiled by eval in the page,
    # which its Content-Security-Policy refuses
    pg.wait_for_function("() => window.splinedeformViewer !== undefined", timeout=30_000)
    pg.problems, pg.requests = problems, requests
    yield pg
    context.close()


def canvas_pixels(page) -> np.ndarray:
    """The WebGL canvas as RGB, with the HTML overlays (title, legend) hidden."""
    # through the CSSOM: the page's Content-Security-Policy refuses an added <style> tag
    page.evaluate("for (const id of ['title', 'help', 'legend'])"
                  " document.getElementById(id).style.visibility = 'hidden'")
    png = page.locator("#view canvas").screenshot()
    return np.asarray(Image.open(io.BytesIO(png)).convert("RGB")).astype(int)


def expected_checksum(surface: Surface, net: np.ndarray) -> float:
    vertices, _ = surface.tessellate(RESOLUTION, control_points=net)
    return viz.vertex_checksum(vertices)


def move_slider(page, value: int) -> None:
    page.eval_on_selector("#slider", """(s, v) => { s.value = String(v);
        s.dispatchEvent(new Event('input', { bubbles: true })); }""", value)


def test_page_is_self_contained(viewer_file):
    text = viewer_file[0].read_text(encoding="utf-8")
    assert not re.search(r"<script[^>]*\bsrc=|<link\b|@import", text)
    assert "three.js r187" in text


def test_canvas_shows_the_surface_without_errors(page, viewer_file):
    _, surface, nets = viewer_file
    assert page.locator("#view canvas").count() == 1
    assert page.evaluate("!!document.querySelector('#view canvas').getContext('webgl2') || "
                         "!!document.querySelector('#view canvas').getContext('webgl')")
    hook = page.evaluate("[splinedeformViewer.frameCount, splinedeformViewer.currentFrame]")
    assert hook == [9, 4]                # opens at the peak: sin(πt) is largest at t = 0.5
    move_slider(page, 0)
    pixels = canvas_pixels(page)
    assert pixels.shape[0] > 300 and pixels.shape[1] > 600
    background = np.array([0xF4, 0xF5, 0xF7])
    assert np.mean(np.any(pixels != background, axis=-1)) > 0.05     # not blank
    # the flat rest state: surface colour, shading of the net's lines and points
    assert len(np.unique(pixels.reshape(-1, 3), axis=0)) >= 8
    assert page.evaluate("splinedeformViewer.vertexChecksum()") == \
        pytest.approx(expected_checksum(surface, nets[0]), rel=1e-12, abs=1e-9)
    # the legend spans 0 .. max |d| of the whole motion
    assert float(page.text_content("#legend-max")) == pytest.approx(viz.viewer_data(
        surface, surface.control_points, [0.0], nets[4:5], RESOLUTION)["vmax"], rel=1e-3)
    assert page.problems == []
    assert all(url.startswith("file:") or url.startswith("data:") for url in page.requests)


def test_the_page_opens_at_the_frame_of_largest_displacement(page, viewer_file):
    _, surface, nets = viewer_file
    assert page.evaluate("splinedeformViewer.currentFrame") == 4
    assert page.evaluate("splinedeformViewer.vertexChecksum()") == \
        pytest.approx(expected_checksum(surface, nets[4]), rel=1e-12, abs=1e-9)
    assert page.inner_text("#time").startswith("t = 0.5")
    assert page.problems == []


def test_time_slider_changes_the_drawn_surface(page, viewer_file):
    _, surface, nets = viewer_file
    move_slider(page, 0)
    before_pixels = canvas_pixels(page)
    before = page.evaluate("splinedeformViewer.vertexChecksum()")
    move_slider(page, 4)                                  # the top of the motion, t = 0.5
    assert page.evaluate("splinedeformViewer.currentFrame") == 4
    after = page.evaluate("splinedeformViewer.vertexChecksum()")
    assert after == pytest.approx(expected_checksum(surface, nets[4]), rel=1e-12, abs=1e-9)
    assert abs(after - before) > 1.0
    assert page.inner_text("#time").startswith("t = 0.5")
    after_pixels = canvas_pixels(page)
    assert np.mean(np.any(after_pixels != before_pixels, axis=-1)) > 0.02
    assert len(np.unique(after_pixels.reshape(-1, 3), axis=0)) > 200   # shaded, coloured
    # the raised plate reaches the hot (yellow) end of the colour scale
    r, g, b = after_pixels[..., 0], after_pixels[..., 1], after_pixels[..., 2]
    assert np.sum((r > 180) & (g > 140) & (b < 90)) > 50
    assert np.sum((before_pixels[..., 0] > 180) & (before_pixels[..., 1] > 140)
                  & (before_pixels[..., 2] < 90)) == 0
    assert page.problems == []


def test_control_net_toggle_and_play(page):
    with_net = canvas_pixels(page)
    page.click("#show-net")
    without_net = canvas_pixels(page)
    assert np.mean(np.any(with_net != without_net, axis=-1)) > 0.002
    page.click("#play")
    page.wait_for_function("() => splinedeformViewer.currentFrame > 0", timeout=15_000)
    assert page.inner_text("#play") == "Pause"
    page.click("#play")
    assert page.evaluate("splinedeformViewer.playing") is False
    assert page.problems == []


def test_viewer_rejects_non_html_name(tmp_path):
    surface, times, nets = deforming_plate()
    with pytest.raises(InputError, match="html"):
        viz.write_viewer(tmp_path / "viewer.txt", surface, surface.control_points, times, nets)
    assert list(tmp_path.iterdir()) == []


def test_title_is_the_given_title_and_time_zero_reads_0(browser, tmp_path):
    surface, times, nets = deforming_plate()
    title = "plate <rising> & falling"
    path = viz.write_viewer(tmp_path / "viewer.html", surface, surface.control_points, times,
                            nets, resolution=8, title=title)
    context = browser.new_context(viewport={"width": 900, "height": 600})
    try:
        pg = context.new_page()
        pg.goto(path.as_uri())
        pg.wait_for_function("window.splinedeformViewer !== undefined", timeout=30_000)
        assert pg.title() == f"splinedeform — {title}"
        assert pg.inner_text("#title") == title
        pg.eval_on_selector("#slider", """s => { s.value = "0";
            s.dispatchEvent(new Event('input', { bubbles: true })); }""")
        assert pg.inner_text("#time").split() == ["t", "=", "0", "(1/9)"]
    finally:
        context.close()
