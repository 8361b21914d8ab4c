"""Bake and undo/redo on the sculpting page, in Debian's Chromium (skipped with the reason
when Chromium or Playwright is missing).

A pulled sheet, released and paused mid-ringing, is baked: its shape becomes the rest shape
(the new rest samples are the old rest plus the displacement), the displacement from the
new rest is zero and the velocity goes on. Undo puts the page back exactly where it was
before the bake (basis, clock, pushes, modal state), redo exactly where it was after.
"""

from __future__ import annotations

import numpy as np
import pytest

# skips this module, saying why, without Chromium or Playwright
from chromium import grab_and_pull, sheet_page  # noqa: E402

SHEET = """
title = "bake sheet"
[surface]
shape = "plane"
cells = 4
[material]
damping = 0.5
w10 = 1.0
w01 = 1.0
[boundary]
u0 = "clamped"
u1 = "clamped"
[solve]
kind = "modes"
"""
R = 9


@pytest.fixture(scope="module")
def page(tmp_path_factory, browser):
    with sheet_page(browser, tmp_path_factory.mktemp("bake"), SHEET, R) as page:
        yield page


def _shape(page) -> tuple[np.ndarray, np.ndarray]:
    rest = np.array(page.evaluate(f"Array.from({{length: {R * R}}}, (_, n) => sculptState.rest(n))"))
    disp = np.array(page.evaluate("sculptState.snapshot().displacement")).reshape(-1, 3)
    return rest, disp


def test_bake_then_undo_and_redo_restore_each_state_exactly(page):
    grab_and_pull(page, (R // 2) * R + R // 2, 60, steps=5)
    page.mouse.up()
    page.wait_for_timeout(150)                      # released: ringing
    page.evaluate("sculptState.setPaused(true)")    # the state holds still from here
    rest0, disp0 = _shape(page)
    before = page.evaluate("sculptState.snapshot()")
    modal0 = page.evaluate("sculptState.modalState()")
    assert np.abs(disp0).max() > 1e-3 and np.abs(modal0["v"]).max() > 0
    page.evaluate("sculptState.bake()")
    assert page.evaluate("sculptState.version") == 2, page.evaluate("sculptState.errors")
    assert "baked" in page.inner_text("#progress")
    rest1, disp1 = _shape(page)
    # the new rest is the shape before: float32 rest samples (2^-24 of |x| ~ 1) and float32
    # Φ_s against the server's float64 net, summed over the 25 modes: 1e-5 of |d| + 1e-6
    scale = np.abs(disp0).max()
    assert np.max(np.abs(rest1 - (rest0 + disp0))) <= 1e-5 * scale + 1e-6
    assert np.abs(disp1).max() == 0.0               # q = 0 was set: no displacement at all
    baked = page.evaluate("sculptState.modalState()")
    assert np.abs(baked["v"]).max() > 0 and baked["t"] == 0     # the velocity goes on
    assert page.evaluate("sculptState.history") == [1, 0]

    page.evaluate("sculptState.undo()")
    assert page.evaluate("sculptState.version") == 1 and page.evaluate("sculptState.errors") == []
    # the state kept before the bake, put back (copies of the same numbers)
    assert page.evaluate("sculptState.modalState()") == modal0
    after_undo = page.evaluate("sculptState.snapshot()")
    assert after_undo["time"] == before["time"] and after_undo["pushes"] == before["pushes"]
    rest2, disp2 = _shape(page)
    # the earlier basis's own rest samples, put back: within 1e-12 of their size, while the
    # baked rest differed from them by the displacement (above 1e-3)
    assert np.max(np.abs(rest2 - rest0)) <= 1e-12 * np.abs(rest0).max()
    # the same q and Φ_s summed by the same loop: equal to the last bit, shown to 1e-12
    assert np.max(np.abs(disp2 - disp0)) <= 1e-12 * scale
    assert page.evaluate("sculptState.history") == [0, 1]

    page.evaluate("sculptState.redo()")
    assert page.evaluate("sculptState.version") == 2
    assert page.evaluate("sculptState.modalState()") == baked
    rest3, _ = _shape(page)
    assert np.array_equal(rest3, rest1)
    assert page.evaluate("sculptState.history") == [1, 0]
    # and it moves on from the baked shape
    page.evaluate("sculptState.setPaused(false)")
    t0 = page.evaluate("sculptState.time")
    page.wait_for_function(f"sculptState.time > {t0 + 0.2}", timeout=30000)
    assert np.abs(_shape(page)[1]).max() > 0
    assert not page.problems and page.evaluate("sculptState.errors") == []


def test_keys_bake_undo_redo_pause_and_the_help(page):
    """B bakes, Ctrl-Z undoes it, Ctrl-Y and Ctrl-Shift-Z redo, Space pauses, ? shows the
    help; every control carries a tooltip in physical words."""
    page.evaluate("sculptState.setPaused(false)")
    page.mouse.click(5, 300)                        # the view has the keyboard
    start = page.evaluate("sculptState.version")
    grab_and_pull(page, (R // 2) * R + 3, 30, steps=3)
    page.mouse.up()
    page.keyboard.press("b")
    page.wait_for_function(f"sculptState.version > {start}", timeout=30000)
    baked = page.evaluate("sculptState.version")
    page.keyboard.press("Control+z")
    page.wait_for_function(f"sculptState.version === {start}", timeout=30000)
    page.keyboard.press("Control+y")
    page.wait_for_function(f"sculptState.version === {baked}", timeout=30000)
    page.keyboard.press("Control+z")
    page.wait_for_function(f"sculptState.version === {start}", timeout=30000)
    page.keyboard.press("Control+Shift+z")
    page.wait_for_function(f"sculptState.version === {baked}", timeout=30000)
    paused = page.evaluate("sculptState.paused")
    page.keyboard.press(" ")
    assert page.evaluate("sculptState.paused") is (not paused)
    page.keyboard.press(" ")
    assert page.evaluate("sculptState.paused") is paused
    page.keyboard.press("?")
    assert page.is_visible("#help-overlay") and "Ctrl" in page.inner_text("#help-overlay")
    page.keyboard.press("Escape")
    assert not page.is_visible("#help-overlay")
    tips = page.evaluate("Object.fromEntries(Array.from(document.querySelectorAll("
                         "'#panel input, #panel select, #panel button')).map((n) => [n.id, n.title]))")
    assert all(tips.values()), [k for k, v in tips.items() if not v]
    assert "tension" in tips["material-w10"] and "bending" in tips["material-w20"]
    assert "stiffness-proportional" in tips["material-rayleigh"]
    assert not page.problems and page.evaluate("sculptState.errors") == []
