"""Pinning on the sculpting page, in Debian's Chromium (skipped with the reason when
Chromium or Playwright is missing): an alt-click on a pulled sheet pins the control point
nearest to the clicked point where it is now (a bake with that point taken out of the free
set), and it stays there while another point is pulled; the export buttons download the
shape shown; two grabs held at once (shift, or two fingers) superpose."""

from __future__ import annotations

import numpy as np
import pytest

# skips this module, saying why, without Chromium or Playwright
from chromium import sheet_page  # noqa: E402

SHEET = """
title = "pin sheet"
[surface]
shape = "plane"
cells = 5
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
R = 11


@pytest.fixture(scope="module")
def page(tmp_path_factory, browser):
    with sheet_page(browser, tmp_path_factory.mktemp("pin"), SHEET, R) as page:
        yield page


def test_a_pinned_point_stays_where_it_was_while_another_is_pulled(page):
    page.click("#show-net")                       # the net's displacement is computed
    centre, other = (R // 2) * R + R // 2, 3 * R + 8
    t0 = page.evaluate(f"sculptState.hold({centre}, [0, 0, -2]); sculptState.time")
    page.wait_for_function(f"sculptState.time > {t0 + 0.4}", timeout=30000)
    page.evaluate("sculptState.setPaused(true)")  # the shape holds still for the pin
    k = page.evaluate(f"sculptState.nearestNet({centre})")
    before = np.array(page.evaluate(f"sculptState.netPosition({k})"))
    rest = np.array(page.evaluate(f"sculptState.netPosition({k}) && sculptState.netDisplacement()")
                    ).reshape(-1, 3)[k]
    assert abs(rest[2]) > 1e-3                    # pulled well away from its rest place
    at = page.evaluate(f"sculptState.screen({centre})")
    page.keyboard.down("Alt")
    page.mouse.click(at["x"], at["y"])
    page.keyboard.up("Alt")
    page.wait_for_function("sculptState.version === 2", timeout=30000)
    assert "pinned control point" in page.evaluate("sculptState.progress")
    assert page.evaluate("sculptState.grabbed") is None          # a pin grabs nothing
    assert page.evaluate("sculptState.freeMask")[k] == 0
    # drawn apart from the other fixed points: blue (PINNED_RGB of paint.js; its neighbour
    # FREE_RGB; stored as float32 colours, so 1e-6), counted
    assert page.evaluate("sculptState.pinnedMask")[k] == 1
    assert sum(page.evaluate("sculptState.pinnedMask")) == 1
    assert np.allclose(page.evaluate(f"sculptState.netColor({k})"), [0.15, 0.35, 0.95], atol=1e-6)
    assert np.allclose(page.evaluate(f"sculptState.netColor({k + 1})"), [0.1, 0.62, 0.2], atol=1e-6)
    assert ", 1 pinned (blue)" in page.inner_text("#paint-info")
    page.evaluate("sculptState.setPaused(false)")
    page.evaluate(f"sculptState.hold({other}, [0, 0.5, -3])")
    moved, neighbour = [], []
    for _ in range(6):                            # six moments 0.1 s of page time apart
        t0 = page.evaluate("sculptState.time")
        page.wait_for_function(f"sculptState.time > {t0 + 0.1}", timeout=30000)
        net = np.array(page.evaluate("sculptState.netDisplacement()")).reshape(-1, 3)
        moved.append(np.abs(net[k]).max())
        neighbour.append(np.abs(net[k + 1]).max())
        position = np.array(page.evaluate(f"sculptState.netPosition({k})"))
    page.evaluate("sculptState.release()")
    # held: no free coordinate maps to it (an empty row of T), so 0 up to 1e-9
    assert max(moved) <= 1e-9
    assert max(neighbour) > 1e-3                  # its neighbour is free and pulled along
    # where it was: the baked net (float64 on the server) against the page's float32 net
    # and Φ_net before the pin: 2^-24 of |x| ~ 1 plus that of |d|, 1e-6
    assert np.max(np.abs(position - before)) <= 1e-6
    assert not page.problems and page.evaluate("sculptState.errors") == []


def test_export_buttons_download_the_shape_shown(page, tmp_path):
    """The .3dm the page downloads holds the net drawn (float32 on the page: 1e-5) and the
    same net, to 1e-12, as the net file downloaded at the same paused moment."""
    rhino3dm = pytest.importorskip("rhino3dm", reason="the .3dm export needs the extra 'cad'")
    from splinedeform.export.nets import read_control_net

    if not page.evaluate("document.getElementById('show-net').checked"):
        page.click("#show-net")                   # the net's displacement is computed
    t0 = page.evaluate(f"sculptState.hold({(R // 2) * R + 3}, [0, 0, -2]); sculptState.time")
    page.wait_for_function(f"sculptState.time > {t0 + 0.3}", timeout=30000)
    page.evaluate("sculptState.setPaused(true)")
    files = {}
    for fmt in ("3dm", "json", "obj"):
        with page.expect_download() as info:
            page.click(f"#export-{fmt}")
        files[fmt] = tmp_path / info.value.suggested_filename
        info.value.save_as(files[fmt])
    drawn = np.array(page.evaluate("Array.from({length: sculptState.freeMask.length}, "
                                   "(_, k) => sculptState.netPosition(k))"))
    page.evaluate("sculptState.release()")
    page.evaluate("sculptState.setPaused(false)")
    assert files["3dm"].name == "pin_sheet-shape.3dm"
    srf = rhino3dm.File3dm.Read(str(files["3dm"])).Objects[0].Geometry
    got = np.array([[srf.Points[i, j].X, srf.Points[i, j].Y, srf.Points[i, j].Z]
                    for i in range(srf.Points.CountU) for j in range(srf.Points.CountV)])
    net = read_control_net(files["json"]).control_points.reshape(-1, 3)
    assert np.abs(net[:, 2]).max() > 1e-3                      # pulled: the shape moved
    # one net through two writers (openNURBS doubles, repr floats): 1e-12
    assert np.max(np.abs(got - net)) <= 1e-12 * np.abs(net).max()
    # the net drawn: float32 rest net and Φ_net on the page, 1e-5 of the size
    assert np.max(np.abs(drawn - net)) <= 1e-5 * np.abs(net).max()
    assert files["obj"].read_text().startswith("# splinedeform surface mesh")
    assert not page.problems and page.evaluate("sculptState.errors") == []


def test_two_grabs_held_at_once_superpose(page):
    """A grab released with shift stays held by its spring; a second grab pulls beside it.
    With both held the page's displacement is the sum of its own closed-form responses to
    each grab's force history alone (linearity), to 1e-6 of the largest."""
    page.evaluate("sculptState.reset()")
    t0 = page.evaluate("sculptState.time")
    page.wait_for_function(f"sculptState.time > {t0 + 0.1}", timeout=30000)   # drawn at rest
    a, b = 3 * R + 4, 6 * R + 5
    first = page.evaluate(f"sculptState.screen({a})")
    page.mouse.move(first["x"], first["y"])
    page.mouse.down()
    for step in range(1, 5):
        page.mouse.move(first["x"], first["y"] + 10 * step)
        page.wait_for_timeout(40)
    page.wait_for_function("sculptState.grabbed && sculptState.grabbed.force", timeout=30000)
    page.keyboard.down("Shift")
    page.mouse.up()                               # shift: the grab stays held
    page.keyboard.up("Shift")
    grabs = page.evaluate("sculptState.grabs")
    assert len(grabs) == 1 and grabs[0]["held"]
    a = grabs[0]["index"]                         # the sample picked under the pointer
    second = page.evaluate(f"sculptState.screen({b})")
    page.mouse.move(second["x"], second["y"])
    page.mouse.down()
    for step in range(1, 5):
        page.mouse.move(second["x"] + 8 * step, second["y"] - 6 * step)
        page.wait_for_timeout(40)
    page.wait_for_timeout(300)
    # a frame has pulled with both and the status line (redone every 250 ms) says so
    page.wait_for_function("sculptState.grabs.length === 2 && sculptState.grabs.every((g) => g.force)"
                           " && sculptState.hud.includes('more held')", timeout=30000)
    page.evaluate("sculptState.setPaused(true)")
    grabs = page.evaluate("sculptState.grabs")
    snap = page.evaluate("sculptState.snapshot()")
    hud = page.evaluate("sculptState.hud")
    page.mouse.up()
    page.keyboard.press("Escape")                 # lets go of the held one too
    assert page.evaluate("sculptState.grabs") == []
    page.evaluate("sculptState.setPaused(false)")
    held = [g for g in grabs if g["held"]]
    assert len(grabs) == 2 and len(held) == 1 and held[0]["index"] == a
    b = next(g["index"] for g in grabs if not g["held"])
    assert b != a
    # both pull (forces of the order of the spring times the pointer's offset, < 10)
    assert all(g["force"] and 0 < np.linalg.norm(g["force"]) < 10 for g in grabs)
    assert "1 more held" in hud
    alone = []
    for index in (a, b):
        pushes = [p for p in snap["pushes"] if p["index"] == index]
        assert pushes and pushes[-1]["t_off"] is None          # still held at the snapshot
        alone.append(np.array(page.evaluate("sculptState.simulate(%s, [%r])[0]" % (
            str(pushes).replace("None", "null").replace("'", '"'), snap["time"]))))
    both = np.asarray(snap["displacement"])
    scale = np.abs(both).max()
    assert np.abs(alone[0]).max() > 1e-3 * scale and np.abs(alone[1]).max() > 1e-3 * scale
    # every mode kept (no correction): the same closed form summed in another order, 1e-6
    assert np.max(np.abs(both - alone[0] - alone[1])) <= 1e-6 * scale
    assert not page.problems and page.evaluate("sculptState.errors") == []


def test_two_fingers_grab_two_points(page, browser):
    """On a touch screen each finger grabs on its own: two touches dragged apart pull two
    points, one down and one up, and lifting them lets both go."""
    context = browser.new_context(viewport={"width": 900, "height": 600}, has_touch=True)
    touch = context.new_page()
    touch.goto(page.url)
    touch.wait_for_function("window.sculptState !== undefined && sculptState.time > 0.1", timeout=60000)
    cdp = context.new_cdp_session(touch)
    a, c = (touch.evaluate(f"sculptState.screen({n})") for n in (3 * R + 4, 6 * R + 5))

    def points(dy: float) -> list[dict]:
        return [{"x": a["x"], "y": a["y"] + dy, "id": 1}, {"x": c["x"], "y": c["y"] - dy, "id": 2}]

    cdp.send("Input.dispatchTouchEvent", {"type": "touchStart", "touchPoints": points(0)[:1]})
    cdp.send("Input.dispatchTouchEvent", {"type": "touchStart", "touchPoints": points(0)})
    for step in range(1, 5):
        cdp.send("Input.dispatchTouchEvent", {"type": "touchMove", "touchPoints": points(8 * step)})
        touch.wait_for_timeout(50)
    touch.wait_for_function("sculptState.grabs.length === 2 && sculptState.grabs.every((g) => g.force)",
                            timeout=30000)
    grabs = touch.evaluate("sculptState.grabs")
    cdp.send("Input.dispatchTouchEvent", {"type": "touchEnd", "touchPoints": []})
    touch.wait_for_function("sculptState.grabs.length === 0", timeout=30000)
    problems = touch.evaluate("sculptState.errors")
    context.close()
    assert grabs[0]["index"] != grabs[1]["index"]
    # dragged down the screen (camera above, z up): pulled down; the other finger up: up
    assert grabs[0]["force"][2] < 0 < grabs[1]["force"][2]
    assert problems == []
