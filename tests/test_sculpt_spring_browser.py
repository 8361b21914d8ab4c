"""The spring of a grab scales with the material (a saved page in Debian's Chromium;
skipped with the reason when Chromium or Playwright is missing): its stiffness is the
stiffness slider times the grabbed point's own stiffness 1/α, α = Σ φ_i(a)²/λ_i, so a sheet
ten times stiffer is pulled with ten times the force for the same drag and follows the
pointer alike."""

from __future__ import annotations

import numpy as np

# skips this module, saying why, without Chromium or Playwright
import chromium  # noqa: E402,F401

from splinedeform.scenario import parse_scenario  # noqa: E402
from splinedeform.sculpt.page import sculpt_page  # noqa: E402
from splinedeform.sculpt.session import Session  # noqa: E402

SHEET = """
[surface]
shape = "plane"
cells = 4
[material]
damping = 1.0
w10 = {w}
w01 = {w}
w20 = {b}
w11 = {b}
w02 = {b}
[boundary]
u0 = "clamped"
u1 = "clamped"
[solve]
kind = "modes"
"""
R = 9


def _force(browser, folder, w: float) -> np.ndarray:
    session = Session(parse_scenario(SHEET.format(w=w, b=0.01 * w), source="s.toml"),
                      resolution=R, modes=None)
    path = folder / f"sheet-{w:g}.html"
    path.write_text(sculpt_page(session.page_payload()), encoding="utf-8")
    page = browser.new_page(viewport={"width": 800, "height": 600})
    page.goto(path.as_uri())
    page.wait_for_function("window.sculptState !== undefined && sculptState.time > 0.1", timeout=60000)
    page.evaluate("sculptState.setPaused(true)")        # at rest, time frozen: F = k (x_p - x)
    sample = (R // 2) * R + R // 2
    at = page.evaluate(f"sculptState.screen({sample})")
    page.mouse.move(at["x"], at["y"])
    page.mouse.down()
    page.mouse.move(at["x"], at["y"] + 30)
    page.wait_for_timeout(300)
    force = np.array(page.evaluate("sculptState.grabbed.force"))
    page.mouse.up()
    page.close()
    return force


def test_the_spring_scales_with_the_stiffness_of_the_material(browser, tmp_path):
    soft, stiff = _force(browser, tmp_path, 1.0), _force(browser, tmp_path, 10.0)
    assert np.linalg.norm(soft) > 0
    # every weight x10: λ_i x10, the same φ_i, so 1/α and the force x10; the same camera
    # and drag on both pages, eigenvectors from two solves (round-off): 1e-6
    assert np.max(np.abs(stiff - 10 * soft)) <= 1e-6 * np.linalg.norm(stiff)
