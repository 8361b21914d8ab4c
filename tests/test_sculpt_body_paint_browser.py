"""A body's free set painted face by face in the sculpting page (Debian's Chromium driven by
Playwright; skipped with the reason when either is missing): the two flat faces of
:mod:`sculpt_body_files` (6 × 6 nets, every boundary edge clamped). Every point is fixed,
then two control points of face 0 are picked on the net (brush 0) and face 1 painted whole
with a wide brush on its surface; applied, the server solves with face 0's two points and
face 1 moving, and Save writes ``boundary.faces_free_points`` for them. A screenshot is
written to the test's folder (printed) for a look."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

# skips this module, saying why, without Chromium or Playwright
from chromium import sculpt_page, sculpt_server, shoot  # noqa: E402

pytest.importorskip("OCP", reason="the body's STEP shell needs OpenCASCADE (the extra 'step')")
from sculpt_body_files import BODY, two_faces  # noqa: E402

R = 10          # samples per direction of each face
N = 6           # each face's net: 3 cubic spans, 6 × 6 points
PICKED = [[2, 2], [3, 3]]


def click(page, at: dict, shift: bool = False) -> None:
    if shift:
        page.keyboard.down("Shift")
    page.mouse.click(at["x"], at["y"])
    if shift:
        page.keyboard.up("Shift")


def test_painting_a_face_frees_its_points_and_the_server_solves_with_them(browser, tmp_path):
    two_faces(tmp_path)
    with sculpt_server(tmp_path, "two.toml", BODY, "--resolution", str(R),
                       "--save", "saved.toml") as url:
        page = sculpt_page(browser, url)
        assert not page.is_disabled("#paint")
        page.check("#paint")
        assert page.evaluate("document.getElementById('show-net').checked")
        page.click("#paint-none")
        assert sum(page.evaluate("sculptState.freeMask")) == 0
        # face 0: two control points picked on the net, brush 0 (exactly the point picked)
        page.fill("#brush", "0")
        for i, j in PICKED:
            k = i * N + j
            assert page.evaluate(f"sculptState.netFace({k})") == {"face": 0, "i": i, "j": j}
            click(page, page.evaluate(f"sculptState.netScreen({k})"))
        # face 1: its surface painted with a wide brush near its four corners; every one
        # of its Greville points (0, 1/9, 1/3, 2/3, 8/9, 1 per direction) lies within
        # 0.5 of one of (1/9, 1/9), (1/9, 8/9), (8/9, 1/9), (8/9, 8/9) (at most 0.32 away)
        page.fill("#brush", "0.5")
        for a, b in ((1, 1), (1, R - 2), (R - 2, 1), (R - 2, R - 2)):
            n = R * R + a * R + b
            assert page.evaluate(f"sculptState.face({n})") == 1
            click(page, page.evaluate(f"sculptState.screen({n})"))
        mask = np.array(page.evaluate("sculptState.freeMask"), bool)
        expect = np.zeros(2 * N * N, bool)
        expect[[i * N + j for i, j in PICKED]] = True
        expect[N * N:] = True
        # flags as 0/1: equal when they differ by less than half a unit
        assert np.abs(mask.astype(int) - expect.astype(int)).max() < 0.5
        # what Apply sends: face 0's points; face 1, all free, is left out (it moves)
        assert page.evaluate("sculptState.freeSet()") == {"faces_free_points": {"0": PICKED}}
        info = page.inner_text("#paint-info")
        assert "(face 0: 2, face 1: 36)" in info and "not applied" in info
        page.click("#apply")
        page.wait_for_function("sculptState.version === 2 || sculptState.errors.length > 0",
                               timeout=60000)
        assert page.evaluate("sculptState.errors") == []
        # the server's answer describes the same set: free_mask, and still_mask holding
        # every point of face 0 but the two picked
        answer = np.array(page.evaluate("sculptState.freeMask"), bool).astype(int)
        assert np.abs(answer - expect.astype(int)).max() < 0.5
        still = np.array(page.evaluate("sculptState.stillMask"), bool)
        assert not still[:N * N][expect[:N * N]].any() and still[:N * N][~expect[:N * N]].all()
        info = page.inner_text("#paint-info")
        assert info.startswith("38 of 72 control points free (green) (face 0: 2, face 1: 36)")
        assert "not applied" not in info
        # a force held on face 0 at point (2, 2), lifting it, moves the two points and nothing
        # else of face 0
        page.uncheck("#paint")
        page.uncheck("#colour")
        centre = R * 3 + 3                                   # (u, v) = (1/3, 1/3) of face 0
        page.evaluate(f"sculptState.hold({centre}, [0, 0, 0.05])")
        page.wait_for_timeout(600)
        page.evaluate("sculptState.setPaused(true)")
        net = np.array(page.evaluate("sculptState.netDisplacement()")).reshape(2, N * N, 3)
        # fixed points are no unknowns: their rows of the modes are empty sums, exactly 0
        assert np.all(net[0][~expect[:N * N]] == 0.0)
        assert np.abs(net[0][expect[:N * N]]).max() > 1e-4
        page.check("#show-net")
        page.eval_on_selector("#paint-info", "node => node.scrollIntoView({block: 'center'})")
        shoot(page, tmp_path / "sculpt-body-paint.png")
        # Save writes the painted set as the scenario key
        reply = page.evaluate("sculptState.save()")
        saved = Path(reply["path"])
        from splinedeform.scenario import load_scenario

        scenario = load_scenario(saved if saved.is_absolute() else tmp_path / saved)
        assert scenario.raw["boundary"]["faces_free_points"] == {"0": PICKED}
        assert not page.problems
        page.close()
