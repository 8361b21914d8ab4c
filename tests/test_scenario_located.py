"""Scenario files that used to fail deep inside the library: each one a located ScenarioError."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from splinedeform import ScenarioError
from splinedeform.pipeline import run
from splinedeform.scenario import build, load_scenario, parse_scenario

BASE = """\
[surface]
shape = "plane"
cells = 3

[material]
w10 = 1.0
w01 = 1.0

[boundary]
u0 = "clamped"
u1 = "clamped"

[[load]]
kind = "uniform"
force = [0.0, 0.0, -1.0]
profile = "step"

[solve]
kind = "dynamic"
t_end = 2.0
frames = 5

[output]
formats = []
"""


def line_of(text: str, start: str) -> int:
    """Line (from 1) of the first line of ``text`` starting with ``start``."""
    return next(i for i, line in enumerate(text.splitlines(), 1) if line.startswith(start))


def run_error(text: str, tmp_path: Path | None = None) -> str:
    """The message of the ScenarioError raised on reading, building or running ``text``."""
    with pytest.raises(ScenarioError) as info:
        run(parse_scenario(text, source="case.toml"), None if tmp_path is None else tmp_path / "out")
    return str(info.value)


def test_periodic_knots_on_a_plane_are_refused_at_the_knots_key():
    text = BASE.replace("cells = 3\n", "cells = 5\nknots = [\"periodic\", \"open\"]\n")
    message = run_error(text)
    assert message.startswith(f"case.toml:{line_of(text, 'knots')}: surface.knots: ")
    assert "not closed in u" in message and "1 apart" in message
