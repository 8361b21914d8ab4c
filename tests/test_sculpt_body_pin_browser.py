"""A pin (alt-click) on a body in the sculpting page, in Debian's Chromium driven by
Playwright (skipped with the reason when either is missing): the two flat faces of
:mod:`sculpt_body_files` (6 × 6 nets, every boundary edge clamped; face 0's row 5 is face
1's row 0). Face 0 is pulled, an alt-click pins the control point under the pointer where
it is (the server bakes and solves with face 0's set less that point), a second one pins a
point of the shared edge, which the page then shows held on both faces, and an alt-click
on a point the clamped edge holds is refused with a message. Save writes the faces' sets.
A screenshot is written to the test's folder (printed) for a look."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

# skips this module, saying why, without Chromium or Playwright
from chromium import sculpt_page, sculpt_server, shoot  # noqa: E402

pytest.importorskip("OCP", reason="the body's STEP shell needs OpenCASCADE (the extra 'step')")
from sculpt_body_files import BODY, two_faces  # noqa: E402

R = 10          # samples per direction of each face: u, v = 0, 1/9, …, 1
N = 6           # each face's net: 3 cubic spans, 6 × 6 points, Greville 0, 1/9, 1/3, 2/3, 8/9, 1


def alt_click(page, sample: int) -> None:
    at = page.evaluate(f"sculptState.screen({sample})")
    page.keyboard.down("Alt")
    page.mouse.click(at["x"], at["y"])
    page.keyboard.up("Alt")


def pulled(page, sample: int, force: list[float]) -> None:
    """A force held at ``sample`` for 0.4 s of page time, then the page paused."""
    t0 = page.evaluate(f"sculptState.hold({sample}, {force}); sculptState.time")
    page.wait_for_function(f"sculptState.time > {t0 + 0.4}", timeout=30000)
    page.evaluate("sculptState.setPaused(true)")


def test_alt_click_pins_a_point_of_a_face_and_a_shared_point_on_both(browser, tmp_path):
    two_faces(tmp_path)
    with sculpt_server(tmp_path, "two.toml", BODY, "--resolution", str(R),
                       "--save", "saved.toml") as url:
        page = sculpt_page(browser, url)
        page.check("#show-net")                          # the net's displacement is computed
        assert not page.is_disabled('#grab-mode option[value="pin"]')
        # face 0 pulled up at (u, v) = (1/3, 1/3); its nearest control point is (2, 2)
        centre = 3 * R + 3
        pulled(page, centre, [0, 0, 0.05])
        k = page.evaluate(f"sculptState.nearestNet({centre})")
        assert page.evaluate(f"sculptState.netFace({k})") == {"face": 0, "i": 2, "j": 2}
        before = np.array(page.evaluate(f"sculptState.netPosition({k})"))
        assert before[2] > 1e-4                          # lifted off its rest place z = 0
        alt_click(page, centre)
        page.wait_for_function("sculptState.version === 2 || sculptState.errors.length > 0",
                               timeout=60000)
        assert page.evaluate("sculptState.errors") == []
        assert "pinned control point [2, 2] of face 0" in page.evaluate("sculptState.progress")
        assert page.evaluate("sculptState.grabbed") is None            # a pin grabs nothing
        # the server solved with it: out of the free set and still (its flags, exactly)
        assert page.evaluate("sculptState.freeMask")[k] == 0
        assert page.evaluate("sculptState.stillMask")[k] == 1
        # where it was: the baked net (float64 on the server, through the STEP file) against
        # the page's float32 net before the pin, 1e-6 of the net's size 2
        after = np.array(page.evaluate(f"sculptState.netPosition({k})"))
        assert np.abs(after - before).max() <= 1e-6 * 2
        # a point of the shared edge: face 0's (5, 3) at (u, v) = (1, 2/3) is face 1's (0, 3)
        edge = (R - 1) * R + 6
        a = page.evaluate(f"sculptState.nearestNet({edge})")
        rows = page.evaluate(f"sculptState.samePoint({a})")
        assert [page.evaluate(f"sculptState.netFace({m})") for m in rows] == [
            {"face": 0, "i": 5, "j": 3}, {"face": 1, "i": 0, "j": 3}]
        page.evaluate("sculptState.setPaused(false)")
        alt_click(page, edge)
        page.wait_for_function("sculptState.version === 3 || sculptState.errors.length > 0",
                               timeout=60000)
        assert page.evaluate("sculptState.errors") == []
        assert "held on every face that has it" in page.evaluate("sculptState.progress")
        free = page.evaluate("sculptState.freeMask")
        still = page.evaluate("sculptState.stillMask")
        assert [free[m] for m in rows] == [0, 0] and [still[m] for m in rows] == [1, 1]
        info = page.inner_text("#paint-info")
        assert info.startswith("69 of 72 control points free (green) (face 0: 34, face 1: 35)")
        # two pins, one of them a point of two faces: two points drawn blue on three rows
        assert ", 2 pinned (blue)" in info
        pinned = page.evaluate("sculptState.pinnedMask")
        assert [m for m, on in enumerate(pinned) if on] == sorted([k, *rows])
        # near the clamped edge u0 (rows 0 and 1 of face 0 held): refused on the page, nothing
        # sent (the sample picked at the edge's screen place may be its neighbour: row 0 or 1)
        alt_click(page, 0 * R + 3)
        page.wait_for_timeout(300)
        message = page.inner_text("#message")
        assert re.search(r"control point \[[01], 2\] of face 0 \(u = .*\) is held already by an "
                         r"edge preset", message), message
        assert page.evaluate("sculptState.version") == 3
        # face 1 pulled: the pinned points stay (no free coordinate maps to them, so their
        # rows of the modes are empty sums: exactly 0) while face 1's interior moves
        pulled(page, R * R + 4 * R + 4, [0, 0, -0.05])
        net = np.array(page.evaluate("sculptState.netDisplacement()")).reshape(-1, 3)
        assert np.all(net[[k, *rows]] == 0.0)
        assert np.abs(net[N * N + 2 * N + 2]).max() > 1e-4
        Path("/tmp/bodypin").mkdir(exist_ok=True)
        shoot(page, tmp_path / "sculpt-body-pin.png")
        page.screenshot(path="/tmp/bodypin/sculpt-body-pin.png")
        # Save writes the faces' sets: face 0 less both pins, face 1 less the shared point
        reply = page.evaluate("sculptState.save()")
        saved = Path(reply["path"])
        from splinedeform.scenario import load_scenario

        scenario = load_scenario(saved if saved.is_absolute() else tmp_path / saved)
        sets = scenario.raw["boundary"]["faces_free_points"]
        every = [[i, j] for i in range(N) for j in range(N)]
        assert sets == {"0": [p for p in every if p not in ([2, 2], [5, 3])],
                        "1": [p for p in every if p != [0, 3]]}
        assert not page.problems
        page.close()
