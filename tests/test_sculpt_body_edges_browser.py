"""A body's boundary edges set one by one in the sculpting page (Debian's Chromium driven by
Playwright; skipped with the reason when either is missing): the two flat faces of
:mod:`sculpt_body_files`, every boundary edge clamped, then face 1's far edge ``u1`` and
bottom edge ``v0`` let go in the boundary panel and re-solved. A screenshot is written to
the test's folder (printed) for a look."""

from __future__ import annotations

import numpy as np
import pytest

# skips this module, saying why, without Chromium or Playwright
from chromium import resolve_in_page, sculpt_page, sculpt_server, shoot  # noqa: E402

pytest.importorskip("OCP", reason="the body's STEP shell needs OpenCASCADE (the extra 'step')")
from sculpt_body_files import BODY, two_faces  # noqa: E402

R = 10


def test_each_boundary_edge_of_a_body_takes_its_own_preset(browser, tmp_path):
    two_faces(tmp_path)
    with sculpt_server(tmp_path, "two.toml", BODY, "--resolution", str(R),
                       "--save", "saved.toml") as url:
        page = sculpt_page(browser, url)
        names = page.eval_on_selector_all("#body-edges .name", "nodes => nodes.map(n => n.textContent)")
        assert names == ["face 0 u0", "face 0 v0", "face 0 v1", "face 1 u1", "face 1 v0", "face 1 v1"]
        page.select_option("#edge-1-u1", "free")
        page.select_option("#edge-1-v0", "free")
        resolve_in_page(page, 2)
        edges = page.evaluate("sculptState.bodyEdges")
        assert {(e["face"], e["edge"]): e["preset"] for e in edges} == {
            (0, "u0"): "clamped", (0, "v0"): "clamped", (0, "v1"): "clamped",
            (1, "u1"): "free", (1, "v0"): "free", (1, "v1"): "clamped"}
        # the panel shows the presets of the basis in use
        assert page.eval_on_selector("#edge-1-u1", "s => s.value") == "free"
        assert page.eval_on_selector("#edge-0-u0", "s => s.value") == "clamped"
        # a force held at face 1's free corner (u, v) = (1, 0) moves it; face 0's clamped
        # corner (0, 0) stays (no unknown there: exactly 0)
        corner, held = R * R + (R - 1) * R, 0
        page.evaluate(f"sculptState.hold({corner}, [0, 0, -1])")
        page.wait_for_timeout(400)
        d = np.asarray(page.evaluate("sculptState.snapshot()")["displacement"]).reshape(-1, 3)
        assert np.linalg.norm(d[corner]) > 1e-3 and np.linalg.norm(d[held]) == 0.0
        page.evaluate("sculptState.release()")
        page.evaluate("sculptState.reset()")
        page.evaluate(f"sculptState.hold({corner}, [0, 0, -0.05])")    # a gentler pull, seen
        page.uncheck("#colour")
        page.wait_for_timeout(600)
        shoot(page, tmp_path / "sculpt-body-edges.png")
        # the edges drawn: one segment per pair of samples along each of the 6 edges
        assert page.evaluate("sculptState.edgeSegments") == 6 * (R - 1)
        assert not page.problems
        page.close()
