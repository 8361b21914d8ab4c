"""A sculpting page kept as a file opens and runs from file://, in Debian's Chromium: the DOM
as the browser saves it ("Webpage, Complete": the old canvas, a banner shown) starts afresh
with one canvas in view, and the page "Save offline page" writes (from the server, and from
an offline copy again) runs on its own. Skipped with the reason when Chromium or Playwright
is missing."""

from __future__ import annotations

from pathlib import Path

import pytest

# skips this module, saying why, without Chromium or Playwright
from chromium import sculpt_page, sculpt_server  # noqa: E402

SHEET = """
title = "kept sheet"
[surface]
shape = "plane"
cells = 6
[material]
damping = 1.0
w10 = 1.0
w01 = 1.0
[boundary]
u0 = "clamped"
u1 = "clamped"
[solve]
kind = "modes"
"""
R = 12


@pytest.fixture(scope="module")
def server(tmp_path_factory):
    folder = tmp_path_factory.mktemp("kept")
    with sculpt_server(folder, "sheet.toml", SHEET, "--resolution", str(R), "--modes", "20") as url:
        yield url, folder


def _opened(browser, path: Path):
    page = browser.new_page(viewport={"width": 900, "height": 600})
    page.problems = []
    page.on("pageerror", lambda exc: page.problems.append(str(exc)))
    page.goto(path.as_uri())
    page.wait_for_function("window.sculptState !== undefined && sculptState.time > 0.2", timeout=60000)
    return page


def _runs_alone(page) -> None:
    """One canvas, filling the view from its top; no banner; offline; a push moves it."""
    assert page.evaluate("sculptState.online") is False
    assert page.evaluate("document.querySelectorAll('canvas').length") == 1
    box = page.evaluate("(() => { const r = document.querySelector('#view canvas')"
                        ".getBoundingClientRect(); return [r.top, r.height]; })()")
    assert box[0] == 0 and box[1] == 600          # in view, not appended below the fold
    assert page.evaluate("getComputedStyle(document.getElementById('message')).display") == "none"
    index = (R // 2) * R + R // 2
    assert page.evaluate(f"sculptState.correction({index}) !== null")   # computed in the page
    page.evaluate(f"sculptState.hold({index}, [0, 0, -1])")
    page.wait_for_function(f"sculptState.displacement({index})[2] < 0", timeout=30000)
    page.evaluate("sculptState.release()")
    assert not page.problems


def test_the_dom_saved_by_the_browser_starts_afresh(server, browser, tmp_path):
    live = sculpt_page(browser, server[0])
    live.click("#save")                              # nothing pushed: a banner says so
    live.wait_for_function("sculptState.errors.length > 0")
    assert live.evaluate("getComputedStyle(document.getElementById('message')).display") == "block"
    path = tmp_path / "complete.html"
    path.write_text(live.content(), encoding="utf-8")   # the DOM now, as "Webpage, Complete"
    live.close()
    page = _opened(browser, path)
    _runs_alone(page)
    page.close()


def test_save_offline_page_writes_a_page_that_runs_alone(server, browser, tmp_path):
    live = sculpt_page(browser, server[0])
    with live.expect_download() as info:
        live.click("#save-page")
    assert info.value.suggested_filename == "kept_sheet-offline.html"
    first = tmp_path / "first.html"
    info.value.save_as(first)
    live.close()
    assert 'name="splinedeform-token" content=""' in first.read_text(encoding="utf-8")
    page = _opened(browser, first)
    _runs_alone(page)
    with page.expect_download() as again:              # and an offline copy saves itself
        page.click("#save-page")
    second = tmp_path / "second.html"
    again.value.save_as(second)
    page.close()
    page = _opened(browser, second)
    _runs_alone(page)
    page.close()


def test_load_surface_from_the_page(server, browser, tmp_path):
    """Load surface… with a net file: the page shows the new surface (its grid of samples
    from the new net), a bad file is refused by name, and Undo goes back."""
    import numpy as np

    import splinedeform as sd
    from splinedeform.export.nets import write_control_nets

    surf = sd.shapes.plane(size=(2.0, 1.0), cells=(5, 3))
    P = surf.control_points.copy()
    P[..., 2] = 0.2 * P[..., 0] * (2.0 - P[..., 0])          # an arch
    path, = write_control_nets(tmp_path, "arch", surf, [0.0], P[None], formats=("json",))
    live = sculpt_page(browser, server[0])
    start = live.evaluate("sculptState.version")
    live.set_input_files("#load-file", str(path))
    live.wait_for_function(f"sculptState.version > {start}", timeout=60000)
    assert "loaded arch.json" in live.evaluate("sculptState.progress")
    # the rest samples are the arch's surface at their parameters: float32 samples, 1e-6
    rest = np.array(live.evaluate(f"Array.from({{length: {R * R}}}, (_, n) => sculptState.rest(n))"))
    uv = np.array(live.evaluate(f"Array.from({{length: {R * R}}}, (_, n) => sculptState.uv(n))"))
    arch = surf.with_control_points(P).evaluate(uv[:, 0], uv[:, 1])
    assert np.max(np.abs(rest - arch)) <= 1e-6
    assert rest[:, 0].max() > 1.99 and rest[:, 2].max() > 0.1  # 2 long and arched: the new surface
    bad = tmp_path / "notes.txt"
    bad.write_text("hello")
    live.set_input_files("#load-file", str(bad))
    live.wait_for_function("sculptState.errors.length > 0")
    assert "notes.txt" in live.evaluate("sculptState.errors")[-1]
    live.evaluate("sculptState.undo()")
    live.wait_for_function(f"sculptState.version === {start}", timeout=30000)
    assert not live.problems
    live.close()
