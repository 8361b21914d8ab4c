"""A saved sculpting page on its own (file://, no server), in Debian's Chromium: it computes
the static correction itself, equal to the server's; the normals at a pole are the limit
normal, not zero. Skipped with the reason when Chromium or Playwright is missing."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

# skips this module, saying why, without Chromium or Playwright
import chromium  # noqa: E402,F401

from splinedeform.scenario import parse_scenario  # noqa: E402
from splinedeform.sculpt.page import sculpt_page  # noqa: E402
from splinedeform.sculpt.session import Session  # noqa: E402

SHEET = """
[surface]
shape = "plane"
cells = 7
[material]
damping = 1.0
w10 = 1.0
w01 = 1.0
w20 = 0.01
w11 = 0.01
w02 = 0.01
[boundary]
u0 = "clamped"
u1 = "pinned"
v0 = "clamped"
[solve]
kind = "modes"
"""

DOME = """
[surface]
shape = "half_sphere"
radius = 1.0
cells = [8, 4]
[material]
damping = 1.0
w10 = 1.0
w01 = 1.0
[boundary]
v0 = "clamped"
v1 = "pole"
[solve]
kind = "modes"
"""


def saved_page(browser, session: Session, folder: Path):
    """The page as the server serves it, saved to a file and opened from there."""
    path = folder / "sculpt.html"
    path.write_text(sculpt_page(session.page_payload()), encoding="utf-8")
    page = browser.new_page(viewport={"width": 800, "height": 600})
    problems: list[str] = []
    requests: list[str] = []
    page.on("pageerror", lambda exc: problems.append(str(exc)))
    page.on("request", lambda r: requests.append(r.url))
    page.goto(path.as_uri())
    page.wait_for_function("window.sculptState !== undefined && sculptState.time > 0.1",
                           timeout=60000)
    assert page.evaluate("sculptState.online") is False
    page.problems, page.requests = problems, requests
    return page


def test_a_saved_page_computes_the_static_correction_itself(browser, tmp_path):
    # 12 of the 64 free coordinates kept: the other 52 enter through the correction
    session = Session(parse_scenario(SHEET, source="sheet.toml"), resolution=11, modes=12)
    assert not session.correction.complete
    page = saved_page(browser, session, tmp_path)
    for index in (5 * 11 + 5, 2 * 11 + 8, 9 * 11 + 1):
        ours = np.array(page.evaluate(f"sculptState.correction({index})"))
        theirs = session.correction.column(index)        # sparse LU of K_r in scipy
        # the page: its own envelope Cholesky of K_r in float64, minus Φ_s Λ⁻¹ Φ_s[a]ᵀ with
        # float32 Φ_s (2^-24 relative per entry, cancelling over 12 modes): 1e-5
        assert np.abs(theirs).max() > 0
        assert np.max(np.abs(ours - theirs)) <= 1e-5 * np.abs(theirs).max()
    # a grab uses it: the HUD says so, nothing went to a server
    assert "static correction" in page.inner_text("#hud")
    assert page.evaluate("sculptState.errors") == [] and not page.problems
    assert all(r.startswith("file:") for r in page.requests), page.requests
    page.close()


def test_normals_at_a_pole_are_the_limit_normal(browser, tmp_path):
    session = Session(parse_scenario(DOME, source="dome.toml"), resolution=12, modes=20)
    page = saved_page(browser, session, tmp_path)
    ru, rv = page.evaluate("sculptState.grid")
    # the pole of the unit half sphere is the last sample column (v = πR/2), at (0, 0, 1);
    # x_u × x_v points outwards, so the limit normal there is +z
    for i in range(ru):
        n = page.evaluate(f"sculptState.rest({i * rv + rv - 1})")
        assert np.allclose(n, [0, 0, 1], atol=1e-5)              # the pole, float32
        normal = np.array(page.evaluate(f"sculptState.normal({i * rv + rv - 1})"))
        # the fan of tangents around the pole is symmetric up to the fit of the sphere
        # (interpolation error ~1e-4 with 4 cubic cells per quarter meridian)
        assert np.linalg.norm(normal) == pytest.approx(1.0, abs=1e-6)
        assert np.linalg.norm(normal - [0, 0, 1]) <= 1e-3
    # one row inwards the normals are the grid's own (x_u × x_v), also near +z
    inner = np.array(page.evaluate(f"sculptState.normal({rv - 2})"))
    assert inner[2] > 0.9
    assert not page.problems
    page.close()


def test_a_periodic_direction_offers_no_edge_condition(browser, tmp_path):
    """The half sphere is periodic in u: u0 and u1 are no edges, so their only choice is
    'free' (disabled); v0 and v1 offer every preset."""
    session = Session(parse_scenario(DOME, source="dome.toml"), resolution=6, modes=10)
    page = saved_page(browser, session, tmp_path)
    options = page.evaluate("""['u0', 'u1', 'v0', 'v1'].map((e) => {
        const s = document.getElementById('boundary-' + e);
        return [s.disabled, Array.from(s.options).map((o) => o.value), s.value]; })""")
    assert options[0] == options[1] == [True, ["free"], "free"]
    assert options[2] == [False, ["free", "pinned", "clamped", "pole"], "clamped"]
    assert options[3] == [False, ["free", "pinned", "clamped", "pole"], "pole"]
    # at rest, before any push, the largest displacement is nothing (not the colour floor)
    page.wait_for_function("document.getElementById('hud').textContent.includes('max |d|')")
    assert re.search(r"max \|d\| = 0(\s|$)", page.inner_text("#hud")), page.inner_text("#hud")
    assert not page.problems
    page.close()
