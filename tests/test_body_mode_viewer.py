"""The viewer's menu of modes (viz/viewer.py, viz/viewer_body.py, the viewer template) in a
real browser: Debian's Chromium driven by Playwright (skipped, saying why, when either is
missing).

A closed box of six faces run as a plate body with ``solve.kind = "modes"``: the page lists
every mode, and choosing mode 3 in the menu draws, at a quarter period, the body's welded
mesh moved by mode 3 on every face, the points being those of the file's data (mode 3's
net displacement evaluated on every face's grid, float32). A single surface's viewer has
the same menu. Screenshots are written to the test's folder (printed) for a look.
"""

from __future__ import annotations

import base64
import json

import numpy as np
import pytest
from scipy.spatial import cKDTree

# skips this module, saying why, without Chromium or Playwright
import chromium  # noqa: E402,F401

r3 = pytest.importorskip("rhino3dm", reason="the 'cad' extra (rhino3dm) is not installed")

from test_body_mode_outputs import sampled_mode  # noqa: E402

from splinedeform import viz  # noqa: E402
from splinedeform.pipeline import run  # noqa: E402
from splinedeform.scenario import load_scenario  # noqa: E402

R = 7


def page_data(path) -> dict:
    text = path.read_text()
    return json.loads(text.split('id="splinedeform-data">', 1)[1].split("</script>", 1)[0])


def decoded(text: str, dtype: str, shape: tuple[int, ...]) -> np.ndarray:
    return np.frombuffer(base64.b64decode(text), dtype).reshape(shape).astype(float)


def open_viewer(browser, path):
    page = browser.new_page(viewport={"width": 900, "height": 600})
    problems: list[str] = []
    page.on("pageerror", lambda exc: problems.append(str(exc)))
    page.on("console", lambda m: problems.append(m.text) if m.type == "error" else None)
    page.goto(path.as_uri())
    page.wait_for_function("() => window.splinedeformViewer !== undefined", timeout=30_000)
    page.problems = problems
    return page


@pytest.fixture(scope="module")
def box_run(tmp_path_factory):
    folder = tmp_path_factory.mktemp("boxviewer")
    model = r3.File3dm()
    model.Objects.AddBrep(r3.Brep.CreateFromBox(r3.Box(r3.BoundingBox(0, 0, 0, 2, 2, 2))))
    assert model.Write(str(folder / "box.3dm"), 7)
    (folder / "box.toml").write_text(
        '[surface]\nshape = "cad"\npath = "box.3dm"\nelevate = 1\nrefine = 1\n\n'
        '[material]\nw10 = 1.0\nw01 = 1.0\nw20 = 0.4\nw02 = 0.4\n\n'
        '[solve]\nkind = "modes"\nmodes = 4\nframes = 5\n\n'
        f'[output]\nformats = ["viewer"]\nresolution = {R}\n')
    return run(load_scenario(folder / "box.toml"), folder / "out"), folder / "out"


def test_choosing_mode_3_moves_every_face(browser, box_run, tmp_path):
    result, out = box_run
    data = page_data(out / "viewer.html")
    N, K = data["vertexCount"], len(result.omegas)
    assert N == 6 * R ** 2 - 12 * R + 8                 # one welded mesh of the six faces
    rest = decoded(data["rest"], "<f4", (N, 3))
    fields = decoded(data["modes"]["fields"], "<f4", (K, N, 3))
    # the file's mode 3 at every point is D_3 evaluated on every face sampled there (the
    # points of an edge or a corner are shared): float32, 1e-6 of the size 2
    points, moved = sampled_mode(result, 3, R)
    for near, d in zip(cKDTree(points).query_ball_point(rest, 2e-6), fields[2]):
        assert near and np.abs(moved[near] - d).max() <= 2e-6

    page = open_viewer(browser, out / "viewer.html")
    labels = page.eval_on_selector_all("#mode option", "options => options.map(o => o.text)")
    assert len(labels) == K and labels[2].startswith("mode 3: ω = ")
    assert page.evaluate("splinedeformViewer.currentMode") == 1
    page.select_option("#mode", "3")
    assert page.evaluate("splinedeformViewer.currentMode") == 3
    page.evaluate("splinedeformViewer.setFrame(1)")      # phase 1/4: sin(2π/4) = 1
    # the drawn positions: float32 rest + a d_3, as the page computes them (in doubles,
    # stored as float32), summed in float64 in the same order: 1e-9 relative
    a = float(np.sin(2 * np.pi * data["times"][1]))
    expect = viz.vertex_checksum((rest + a * fields[2]).astype(np.float32))
    assert abs(page.evaluate("splinedeformViewer.vertexChecksum()") - expect) <= \
        1e-9 * abs(expect)
    motion = np.asarray(page.evaluate("splinedeformViewer.faceMotion()"))
    # every face moves: each by at least a tenth of the body's largest (mode 3's faces
    # move by 0.82 to 1 of it, measured)
    assert motion.shape == (6,) and motion.min() > 0.1 * motion.max() > 0
    assert float(page.text_content("#legend-max")) == pytest.approx(
        np.linalg.norm(fields[2], axis=1).max(), rel=1e-3)
    shot = tmp_path / "viewer-body-mode3.png"
    page.screenshot(path=str(shot))
    print(f"\nscreenshot: {shot}")
    assert not page.problems
    page.close()


def test_a_single_surface_has_the_same_menu(browser, tmp_path):
    (tmp_path / "drum.toml").write_text(
        '[surface]\nshape = "plane"\ncells = 4\n\n[material]\nw10 = 1.0\nw01 = 1.0\n\n'
        '[boundary]\nu0 = "pinned"\nu1 = "pinned"\nv0 = "pinned"\nv1 = "pinned"\n\n'
        '[solve]\nkind = "modes"\nmodes = 3\nframes = 5\n\n'
        '[output]\nformats = ["viewer"]\nresolution = 9\n')
    result = run(load_scenario(tmp_path / "drum.toml"), tmp_path / "out")
    page = open_viewer(browser, tmp_path / "out" / "viewer.html")
    assert page.evaluate("splinedeformViewer.modeCount") == 3
    page.evaluate("splinedeformViewer.setMode(2)")
    page.evaluate("splinedeformViewer.setFrame(1)")
    surface = result.built.surface
    vertices, _ = surface.tessellate(9, control_points=surface.control_points
                                     + result.mode_nets[1])
    # float32 data on the page against float64 here: 1e-6 relative
    assert page.evaluate("splinedeformViewer.vertexChecksum()") == pytest.approx(
        viz.vertex_checksum(vertices), rel=1e-6)
    assert not page.problems
    page.close()
