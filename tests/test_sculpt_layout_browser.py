"""The sculpting page's layout on a phone, a tablet and short desktop screens, in Debian's
Chromium (skipped with the reason when Chromium or Playwright is missing): at 390 × 844 the
3-D view takes the full width with the controls below it; at 720 and 800 px of height Save
(and the other session buttons) can be clicked without scrolling. Screenshots are written
to the test's folder (printed) for a look."""

from __future__ import annotations

import pytest

# skips this module, saying why, without Chromium or Playwright
import chromium  # noqa: E402,F401

from splinedeform.scenario import parse_scenario  # noqa: E402
from splinedeform.sculpt.page import sculpt_page  # noqa: E402
from splinedeform.sculpt.session import Session  # noqa: E402

SHEET = """
title = "layout sheet"
[surface]
shape = "plane"
cells = 4
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


@pytest.fixture(scope="module")
def page_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("layout") / "sculpt.html"
    session = Session(parse_scenario(SHEET, source="sheet.toml"), resolution=9, modes=None)
    path.write_text(sculpt_page(session.page_payload()), encoding="utf-8")
    return path


def _open(browser, path, width, height):
    page = browser.new_page(viewport={"width": width, "height": height})
    page.goto(path.as_uri())
    page.wait_for_function("window.sculptState !== undefined && sculptState.time > 0.1", timeout=60000)
    return page


def _clickable(page, selector: str) -> bool:
    """In the viewport, unscrolled, and the element found under its own centre."""
    return page.evaluate(f"""(() => {{
        const node = document.querySelector({selector!r}), r = node.getBoundingClientRect();
        const x = r.left + r.width / 2, y = r.top + r.height / 2;
        return r.width > 0 && r.top >= 0 && r.bottom <= innerHeight && r.left >= 0 &&
               r.right <= innerWidth && document.elementFromPoint(x, y) === node;
    }})()""")


def test_on_a_phone_the_view_takes_the_full_width_with_the_controls_below(browser, page_file):
    page = _open(browser, page_file, 390, 844)
    view = page.evaluate("(() => { const r = document.querySelector('#view canvas')"
                         ".getBoundingClientRect(); return [r.left, r.width, r.top, r.bottom]; })()")
    panel_top = page.evaluate("document.getElementById('panel').getBoundingClientRect().top")
    assert view[0] == 0 and view[1] == 390                 # the full width
    assert view[3] - view[2] > 0.5 * 844 - 1               # more than half the height
    assert panel_top >= view[3] - 1                        # the controls below the view
    for button in ("#save", "#bake", "#undo", "#pause"):
        assert _clickable(page, button), button
    shot = page_file.parent / "phone-390x844.png"
    page.screenshot(path=str(shot))
    print(f"\nscreenshot: {shot}")
    page.close()


@pytest.mark.parametrize("height", [720, 800])
def test_save_is_in_view_without_scrolling(browser, page_file, height):
    page = _open(browser, page_file, 1280, height)
    assert page.evaluate("document.getElementById('panel').scrollTop") == 0
    for button in ("#save", "#bake", "#export-3dm", "#save-page"):
        assert _clickable(page, button), button
    shot = page_file.parent / f"desktop-1280x{height}.png"
    page.screenshot(path=str(shot))
    print(f"\nscreenshot: {shot}")
    page.close()
