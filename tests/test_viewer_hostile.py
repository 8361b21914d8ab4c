"""A hostile name or title in a shared control net or scenario runs no script in viewer.html.

The page is opened in headless Chromium (Debian's ``/usr/bin/chromium`` through Playwright):
the name must show as text in the page, no element may come from it, the payload's script
must not run, and the Content-Security-Policy must let the page's own scripts run (no
violation, no error) while refusing any other inline script.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from splinedeform import BSplineBasis, Surface
from splinedeform.export import write_control_nets
from splinedeform.pipeline import run
from splinedeform.scenario import load_scenario

# skips this module, saying why, without Chromium or Playwright
import chromium  # noqa: E402,F401

#: every trick at once: closing the script, an element with a handler, the placeholders the
#: page is filled from, a line separator that ends a JavaScript string in old engines
HOSTILE = ('x</script><img src=x onerror="window.pwned=1"><script>window.pwned=2</script>'
           ' __SPLINEDEFORM_DATA__ /*__SPLINEDEFORM_THREE__*/ __SPLINEDEFORM_CSP__ '
           '__SPLINEDEFORM_TITLE__ \u2028 \u2029 <svg onload="window.pwned=3"> &amp; end')

SCENARIO = """\
title = {title}
[surface]
shape = "file"
path = "net.json"
[material]
w10 = 1.0
w01 = 1.0
[boundary]
u0 = "clamped"
[[load]]
kind = "uniform"
force = [0.0, 0.0, -1.0]
[solve]
kind = "dynamic"
t_end = 1.0
frames = 4
[output]
formats = ["viewer", "report"]
resolution = 8
"""

#: records Content-Security-Policy violations before any script of the page runs
WATCH = ("window.violations = [];"
         "document.addEventListener('securitypolicyviolation',"
         " e => window.violations.push(e.violatedDirective + ' ' + e.blockedURI));")


@pytest.fixture(scope="module")
def hostile_viewer(tmp_path_factory) -> Path:
    import json

    folder = tmp_path_factory.mktemp("hostile")
    b = BSplineBasis(2, 3, 1.0, "open")
    gu, gv = np.meshgrid(b.greville(), b.greville(), indexing="ij")
    surface = Surface(np.stack([gu, gv, 0 * gu], -1), b, b, name=HOSTILE)
    write_control_nets(folder, "net", surface, [0.0], surface.control_points[None])
    (folder / "case.toml").write_text(SCENARIO.format(title=json.dumps(HOSTILE)))
    run(load_scenario(folder / "case.toml"), folder / "out")
    return folder / "out" / "viewer.html"


def open_page(browser, path: Path):
    context = browser.new_context(viewport={"width": 800, "height": 600})
    page = context.new_page()
    page.problems = []
    page.on("console", lambda m: page.problems.append(m.text) if m.type == "error" else None)
    page.on("pageerror", lambda e: page.problems.append(f"uncaught: {e}"))
    page.add_init_script(WATCH)
    page.goto(path.as_uri())
    return context, page


def test_a_hostile_name_shows_as_text_and_runs_nothing(browser, hostile_viewer):
    context, page = open_page(browser, hostile_viewer)
    try:
        page.wait_for_function("() => window.splinedeformViewer !== undefined", timeout=30_000)
        assert page.evaluate("window.splinedeformViewer.frameCount") == 4
        page.wait_for_timeout(300)                    # let an onerror/onload fire if any
        assert page.evaluate("window.pwned") is None
        assert page.evaluate("document.querySelector('#title').textContent") == HOSTILE
        assert page.evaluate("document.title") == "splinedeform — " + HOSTILE
        assert page.evaluate("document.querySelectorAll('img, svg').length") == 0
        assert page.evaluate("document.querySelectorAll('script').length") == 3
        assert page.evaluate("window.violations") == []   # the page's own scripts are allowed
        assert page.problems == []
    finally:
        context.close()


def test_the_policy_refuses_any_other_inline_script(browser, hostile_viewer, tmp_path):
    # As if escaping had failed: an extra inline script and handler put into the page.
    text = hostile_viewer.read_text(encoding="utf-8")
    injected = tmp_path / "viewer.html"
    injected.write_text(text.replace("</body>", "<script>window.pwned=4</script>"
                                     '<img src="data:," onerror="window.pwned=5"></body>'),
                        encoding="utf-8")
    context, page = open_page(browser, injected)
    try:
        page.wait_for_function("() => window.splinedeformViewer !== undefined", timeout=30_000)
        page.wait_for_timeout(300)
        assert page.evaluate("window.pwned") is None
        violations = page.evaluate("window.violations")
        assert any(v.startswith("script-src") for v in violations), violations
    finally:
        context.close()


def test_the_report_shows_the_hostile_title_as_text(hostile_viewer):
    text = (hostile_viewer.parent / "report.md").read_text(encoding="utf-8")
    assert "<img" not in text and "<script" not in text and "<svg" not in text
