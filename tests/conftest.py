"""Fixtures shared by the test modules."""

from __future__ import annotations

import pytest


@pytest.fixture(scope="module")
def browser():
    """A headless Chromium for the module (the module skips itself when there is none: it
    imports :mod:`chromium` first)."""
    from chromium import launched

    with launched() as b:
        yield b
