"""Small sweep files and their base scenarios for the sweep tests (written into a folder)."""

from __future__ import annotations

from pathlib import Path

#: a clamped membrane pushed at a point, solved in closed form: small enough that a case
#: takes milliseconds, dynamic so that a shared model's modal basis is reused
MEMBRANE = """\
title = "membrane"

[surface]
shape = "plane"
size = 1.0
cells = 5

[material]
damping = 0.5
w10 = 1.0
w01 = 1.0

[boundary]
u0 = "clamped"
u1 = "clamped"
v0 = "clamped"
v1 = "clamped"

[[load]]
kind = "point"
at = [0.5, 0.5]
force = [0.0, 0.0, -1.0]
profile = "step"

[solve]
kind = "dynamic"
t_end = 2.0
frames = 9
modes = 3

[output]
formats = []
probes = [[0.5, 0.5], [0.3, 0.6]]
"""


def write(folder: Path, sweep: str, scenario: str = MEMBRANE, name: str = "study.toml") -> Path:
    """``folder/base.toml`` (the scenario) and ``folder/<name>`` (the sweep); the sweep's path."""
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "base.toml").write_text(scenario, encoding="utf-8")
    path = folder / name
    path.write_text(sweep, encoding="utf-8")
    return path
