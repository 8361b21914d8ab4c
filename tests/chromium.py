"""Debian's Chromium driven by Playwright for Python, for the browser tests.

A test module imports this first: without Chromium at ``CHROMIUM`` or without Playwright
the import skips the whole module, saying which is missing. Never a browser download.
"""

from __future__ import annotations

import signal
import subprocess
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import pytest

CHROMIUM = "/usr/bin/chromium"
ARGS = ["--no-sandbox", "--disable-gpu", "--enable-unsafe-swiftshader",
        "--disable-background-networking", "--disable-component-update", "--disable-sync",
        "--no-first-run"]

if not Path(CHROMIUM).exists():
    pytest.skip(f"Chromium is not installed at {CHROMIUM} (Debian package `chromium`)",
                allow_module_level=True)
sync_api = pytest.importorskip("playwright.sync_api",
                               reason="Playwright for Python is not installed (extra `test`)")


@contextmanager
def launched() -> Iterator[object]:
    """One headless Chromium for a module's tests."""
    with sync_api.sync_playwright() as p:
        browser = p.chromium.launch(executable_path=CHROMIUM, args=ARGS)
        try:
            yield browser
        finally:
            browser.close()


@contextmanager
def sculpt_server(folder: Path, name: str, scenario: str, *flags: str) -> Iterator[str]:
    """``splinedeform sculpt NAME --no-browser *flags`` run in ``folder``, NAME holding
    the text ``scenario``.

    Yields the page's address; on leaving, stops the server with SIGINT (Ctrl-C) and checks
    that it exited cleanly.
    """
    pytest.importorskip("starlette", reason="the sculpt server needs the extra 'sculpt'")
    pytest.importorskip("uvicorn", reason="the sculpt server needs the extra 'sculpt'")
    (folder / name).write_text(scenario)
    proc = subprocess.Popen([sys.executable, "-m", "splinedeform.cli", "sculpt", name,
                             "--no-browser", *flags], cwd=folder,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    line = proc.stdout.readline() if proc.stdout else ""
    if "http://" not in line:
        proc.kill()
        pytest.fail(f"sculpt did not start: {line!r} {proc.stderr.read() if proc.stderr else ''}")
    try:
        yield line.split()[2]
    finally:
        proc.send_signal(signal.SIGINT)
        assert proc.wait(timeout=30) == 0


def sculpt_page(browser: object, url: str, ready: float = 0.2):
    """The sculpting page at ``url``, once its clock has passed ``ready``; ``page.problems``
    collects uncaught errors."""
    page = browser.new_page(viewport={"width": 900, "height": 600})
    problems: list[str] = []
    page.on("pageerror", lambda exc: problems.append(str(exc)))
    page.goto(url)
    page.wait_for_function(f"window.sculptState !== undefined && sculptState.time > {ready}",
                           timeout=60000)
    page.problems = problems
    return page


def grab_and_pull(page, index: int, dy: float, steps: int = 6) -> int:
    """Press on sample ``index`` of the sculpting page and move the pointer ``dy`` pixels down
    the screen in ``steps`` moves 40 ms apart, the button held; returns the grabbed sample."""
    at = page.evaluate(f"sculptState.screen({index})")
    page.mouse.move(at["x"], at["y"])
    page.mouse.down()
    grabbed = page.evaluate("sculptState.grabbed")
    assert grabbed is not None, "the press on the surface did not grab it"
    for step in range(1, steps + 1):
        page.mouse.move(at["x"], at["y"] + dy * step / steps)
        page.wait_for_timeout(40)
    return grabbed["index"]


@contextmanager
def sheet_page(browser: object, folder: Path, scenario: str, resolution: int) -> Iterator[object]:
    """The sculpting page of ``scenario`` (served from ``folder`` at ``resolution``, saving to
    ``saved.toml``), closed on leaving."""
    with sculpt_server(folder, "sheet.toml", scenario, "--resolution", str(resolution),
                       "--save", "saved.toml") as url:
        page = sculpt_page(browser, url)
        try:
            yield page
        finally:
            page.close()



def resolve_in_page(page, version: int) -> None:
    """Press Re-solve and wait for basis ``version``; the page shows no error."""
    page.click("#resolve")
    page.wait_for_function(f"sculptState.version === {version} || sculptState.errors.length > 0",
                           timeout=60000)
    assert page.evaluate("sculptState.errors") == []


def shoot(page, path: Path) -> None:
    """A screenshot of ``page`` at ``path``, named on the output for a look."""
    page.screenshot(path=str(path))
    print(f"\nscreenshot: {path}")
