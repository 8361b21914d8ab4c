"""A body in the browser (Debian's Chromium driven by Playwright; skipped with the reason
when either is missing): the sculpting page of two faces served by `splinedeform sculpt`,
and the viewer.html of a body run. Each draws every face: the page's triangles are the
faces' grids (none joining two faces), a grab lands on the face under the pointer and the
shared edge moves as one; the viewer's drawn vertices are the body's welded mesh.
Screenshots are written to the test's folder (printed) for a look."""

from __future__ import annotations

import json

import numpy as np
import pytest

# skips this module, saying why, without Chromium or Playwright
from chromium import grab_and_pull, sculpt_page, sculpt_server  # noqa: E402

pytest.importorskip("OCP", reason="the body's STEP shell needs OpenCASCADE (the extra 'step')")
from sculpt_body_files import BODY, two_faces  # noqa: E402

R = 10          # samples per direction of each face


def test_the_sculpt_page_of_a_body_draws_and_pulls_every_face(browser, tmp_path):
    two_faces(tmp_path)
    with sculpt_server(tmp_path, "two.toml", BODY, "--resolution", str(R),
                       "--save", "saved.toml") as url:
        page = sculpt_page(browser, url)
        assert page.evaluate("sculptState.faceCount") == 2
        assert page.evaluate("sculptState.triangleCount()") == 2 * 2 * (R - 1) ** 2
        # a sample of face 1 (the right one), two rows from the shared edge
        index = grab_and_pull(page, R * R + 2 * R + R // 2, 60.0)
        assert page.evaluate(f"sculptState.face({index})") == 1
        page.wait_for_timeout(300)
        assert "of face 1" in page.evaluate("sculptState.hud")
        # the shared edge: face 0's last row of samples and face 1's first, the same points
        snap = page.evaluate("sculptState.snapshot()")
        d = np.asarray(snap["displacement"]).reshape(2, R, R, 3)
        rest = np.array([page.evaluate(f"sculptState.rest({n})") for n in range(2 * R * R)])
        rest = rest.reshape(2, R, R, 3)
        # float32 rest positions on the page: 1e-6 of the body's size (2)
        assert np.abs(rest[0, -1] - rest[1, 0]).max() <= 2e-6
        scale = np.abs(d).max()
        assert scale > 1e-3 and np.abs(d[0]).max() > 0.05 * scale     # face 0 moves too
        # float32 modes summed in float64: 1e-5 of the displacement
        assert np.abs(d[0, -1] - d[1, 0]).max() <= 1e-5 * scale
        shot = tmp_path / "sculpt-body.png"
        page.screenshot(path=str(shot))
        print(f"\nscreenshot: {shot}")
        page.mouse.up()
        assert not page.problems
        page.close()


def test_the_viewer_of_a_body_run_shows_every_face(browser, tmp_path):
    from typer.testing import CliRunner

    from splinedeform import cli, viz

    two_faces(tmp_path)
    scenario = tmp_path / "two.toml"
    scenario.write_text(BODY.replace('kind = "modes"', 'kind = "static"') +
                        '[[load]]\nkind = "pressure"\nq = 1.0\n'
                        '[output]\nformats = ["viewer", "report"]\nresolution = 9\n')
    out = tmp_path / "out"
    result = CliRunner().invoke(cli.app, ["run", str(scenario), "-o", str(out)])
    assert result.exit_code == 0, result.output
    report = json.loads((out / "report.json").read_text())
    assert report["body"]["faces"] == [0, 1]
    text = (out / "viewer.html").read_text()
    data = json.loads(text.split('id="splinedeform-data">', 1)[1].split("</script>", 1)[0])
    page = browser.new_page(viewport={"width": 900, "height": 600})
    problems: list[str] = []
    page.on("pageerror", lambda exc: problems.append(str(exc)))
    page.goto((out / "viewer.html").as_uri())
    page.wait_for_function("() => window.splinedeformViewer !== undefined", timeout=30_000)
    assert page.evaluate("splinedeformViewer.patchCount") == 2
    # the welded mesh of 2 faces of 9 × 9 samples: the 9 points of the shared edge once
    assert data["vertexCount"] == 2 * 81 - 9
    assert page.evaluate("splinedeformViewer.triangleCount") == 2 * 2 * 8 * 8
    frames = np.frombuffer(__import__("base64").b64decode(data["frames"]), "<f4").reshape(
        len(data["times"]), -1, 3)
    page.evaluate(f"splinedeformViewer.setFrame({len(data['times']) - 1})")
    expect = viz.vertex_checksum(frames[-1])
    # float32 positions summed in float64 on both sides, in the same order: 1e-9 relative
    assert abs(page.evaluate("splinedeformViewer.vertexChecksum()") - expect) <= 1e-9 * abs(expect)
    shot = tmp_path / "viewer-body.png"
    page.screenshot(path=str(shot))
    print(f"\nscreenshot: {shot}")
    assert not problems
    page.close()
