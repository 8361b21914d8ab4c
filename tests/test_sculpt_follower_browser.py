"""Heavy damping on the sculpting page (a saved page, its own static correction, in
Debian's Chromium): a unit force held 0.6 s dents the sheet as the whole dynamics does, not
by the static part of the omitted modes at once. Skipped with the reason when Chromium or
Playwright is missing."""

from __future__ import annotations

import numpy as np

# skips this module, saying why, without Chromium or Playwright
import chromium  # noqa: E402,F401

from splinedeform.scenario import parse_scenario  # noqa: E402
from splinedeform.sculpt import Push, sculpt_basis  # noqa: E402
from splinedeform.sculpt.correction import follower  # noqa: E402
from splinedeform.sculpt.page import sculpt_page  # noqa: E402
from splinedeform.sculpt.session import Session  # noqa: E402
from splinedeform.sculpt.state import modal_history  # noqa: E402

HONEY = """
[surface]
shape = "plane"
cells = 7
[material]
damping = 1e8
w10 = 1.0
w01 = 1.0
w20 = 0.01
w11 = 0.01
w02 = 0.01
[boundary]
u0 = "clamped"
u1 = "clamped"
v0 = "clamped"
v1 = "clamped"
[solve]
kind = "modes"
"""
R = 11


def test_a_held_force_under_heavy_damping_creeps_as_the_dynamics(browser, tmp_path):
    session = Session(parse_scenario(HONEY, source="honey.toml"), resolution=R, modes=12)
    assert not session.correction.complete
    path = tmp_path / "honey.html"
    path.write_text(sculpt_page(session.page_payload()), encoding="utf-8")
    page = browser.new_page(viewport={"width": 800, "height": 600})
    problems: list[str] = []
    page.on("pageerror", lambda exc: problems.append(str(exc)))
    page.goto(path.as_uri())
    page.wait_for_function("window.sculptState !== undefined && sculptState.time > 0.1", timeout=60000)
    a = 5 * R + 5
    assert page.evaluate(f"sculptState.correction({a}) !== null")     # computed in the page
    t_on = page.evaluate(f"sculptState.hold({a}, [0, 0, -1]); sculptState.time")
    page.wait_for_function(f"sculptState.time > {t_on + 0.6}", timeout=60000)
    page.evaluate("sculptState.setPaused(true)")
    snap = page.evaluate("sculptState.snapshot()")
    page.evaluate("sculptState.release()")
    got = np.asarray(snap["displacement"]).reshape(-1, 3)[a, 2]
    held = snap["time"] - t_on
    model = session.basis.model
    basis, full = sculpt_basis(model, R, 12), sculpt_basis(model, R)
    u, v = float(basis.samples_u[a // R]), float(basis.samples_v[a % R])
    truth = (full.phi_samples @ modal_history(full, [Push(u, v, (0, 0, -1), 0.0)], [held])[0])[a, 2]
    twin = ((basis.phi_samples @ modal_history(basis, [Push(u, v, (0, 0, -1), 0.0)], [held])[0])[a, 2]
            + session.correction.column(a)[a] * follower(basis, [((0, 0, -1), 0.0, np.inf)], held)[2])
    instant = session.correction.column(a)[a] * -1.0
    print(f"\nheld {held:.3f} s under damping 1e8: page {got:.3e}, twin {twin:.3e}, "
          f"all modes {truth:.3e}, instant static correction {instant:.3e}")
    # the page equals its Python twin to 1e-5 (float32 Φ_s and correction column)
    assert abs(got - twin) <= 1e-5 * abs(twin)
    # and never dents more than the whole dynamics (1e-5: the same float32 rounding)
    assert got < 0 and abs(got) <= abs(truth) * (1 + 1e-5)
    assert abs(instant) > 100 * abs(truth)
    assert not problems
    page.close()
