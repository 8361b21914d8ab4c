"""A trimmed disc in the sculpting page (Debian's Chromium driven by Playwright; skipped
with the reason when either is missing): the page draws the clipped mesh only, a grab at
the disc's centre moves it, and a press on a cut-away corner is refused with a message.
A screenshot is written to the test's folder (printed) for a look."""

from __future__ import annotations

import numpy as np

# skips this module, saying why, without Chromium or Playwright
from chromium import grab_and_pull, sculpt_page, sculpt_server, shoot  # noqa: E402
from test_sculpt_trimmed import CENTRE, DISC, R


def test_a_trimmed_disc_is_drawn_grabbed_inside_and_refused_outside(browser, tmp_path):
    from splinedeform.scenario import build, parse_scenario
    from splinedeform.sculpt.modal import sculpt_basis

    basis = sculpt_basis(build(parse_scenario(DISC, source="disc.toml")).model, R)
    with sculpt_server(tmp_path, "disc.toml", DISC, "--resolution", str(R),
                       "--save", "saved.toml") as url:
        page = sculpt_page(browser, url)
        assert page.evaluate("sculptState.sampleCount") == basis.sample_count
        # the clipped mesh, not the grid: triangle counts are integers
        assert page.evaluate("sculptState.triangleCount()") == len(basis.trimmed.triangles)
        assert page.evaluate("sculptState.triangleCount()") < 2 * (R - 1) ** 2
        assert "clipped to the trims" in page.evaluate("sculptState.hud")
        # a press on the cut-away corner (1, 0) (in view; (0, 0) is off the left): no grab,
        # a message naming the point and the trims
        corner = page.evaluate(f"sculptState.screen({R * (R - 1)})")
        assert 0 < corner["x"] < 900 and 0 < corner["y"] < 600
        page.mouse.move(corner["x"], corner["y"])
        page.mouse.down()
        assert page.evaluate("sculptState.grabbed") is None
        page.mouse.up()
        words = page.evaluate("sculptState.errors")
        assert words and "outside the trims" in words[-1] and "u = 1.000, v = 0.000" in words[-1]
        # a grab at the centre pulls the disc; its rim (the crossings) stays held
        assert grab_and_pull(page, CENTRE, 60.0) == CENTRE
        page.wait_for_timeout(300)
        snap = page.evaluate("sculptState.snapshot()")
        d = np.asarray(snap["displacement"]).reshape(-1, 3)
        centre = np.linalg.norm(d[CENTRE])
        assert centre > 1e-3
        # Nitsche's held rim moves by the discretisation error only (3e-4 of the centre in
        # the static test; 1e-3 allowed, float32 modes add 1e-5)
        assert np.linalg.norm(d[R * R:], axis=1).max() <= 1e-3 * centre
        shoot(page, tmp_path / "sculpt-trimmed.png")
        page.mouse.up()
        assert not page.problems
        page.close()
