"""Save on a surface read from a file: the saved scenario names the file relative to
itself (a copy beside it when the file lies outside its folder), so ``splinedeform run``
replays it without ``--allow-outside-paths`` and reads the same surface."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from splinedeform.scenario import build, load_scenario
from splinedeform.sculpt.messages import PushMessage, SaveMessage
from splinedeform.sculpt.session import Session

SCENARIO = """
[surface]
shape = "file"
path = "grid.npy"
cells = 3
degree = 2
[material]
w10 = 1.0
w01 = 1.0
damping = 1.0
[boundary]
u0 = "clamped"
[solve]
kind = "modes"
"""
R = 5


def _session(folder: Path, save: Path) -> Session:
    folder.mkdir(parents=True, exist_ok=True)
    u = np.linspace(0.0, 1.0, 7)
    # z = u v lies in the spline space: the fit reproduces it (see test_scenario.py)
    grid = np.stack(np.broadcast_arrays(u[:, None], u[None, :], u[:, None] * u[None, :]), -1)
    np.save(folder / "grid.npy", grid)
    (folder / "shape.toml").write_text(SCENARIO)
    return Session(load_scenario(folder / "shape.toml"), resolution=R, modes=None,
                   save_path=save)


def _save(session: Session) -> Path:
    push = PushMessage(index=3 * R + 2, force=(0.0, 0.0, -1.0), t_on=0.0, t_off=0.4)
    path, _ = session.save(SaveMessage(version=session.version, t_end=1.0, pushes=[push]))
    return path


def test_a_file_inside_the_save_folder_is_named_relative(tmp_path):
    session = _session(tmp_path / "inputs", tmp_path / "session.toml")
    saved = _save(session)
    assert 'path = "inputs/grid.npy"' in saved.read_text()
    again = load_scenario(saved)                              # no outside path: accepted
    assert again.surface.path == (tmp_path / "inputs" / "grid.npy").resolve()
    assert not (tmp_path / "grid.npy").exists()                # nothing copied


def test_a_file_outside_is_copied_beside_the_save_and_run_replays_it(tmp_path):
    session = _session(tmp_path / "elsewhere", tmp_path / "out" / "session.toml")
    (tmp_path / "out").mkdir()
    (tmp_path / "out" / "grid.npy").write_bytes(b"another file of the same name")
    saved = _save(session)
    copy = tmp_path / "out" / "session-grid.npy"              # the other grid.npy is kept
    assert (tmp_path / "out" / "grid.npy").read_bytes() == b"another file of the same name"
    assert copy.read_bytes() == (tmp_path / "elsewhere" / "grid.npy").read_bytes()
    assert 'path = "session-grid.npy"' in saved.read_text()
    # the same control net as the session's (the same fit of the same points: to rounding)
    replayed = build(load_scenario(saved)).surface.control_points
    assert np.allclose(replayed, session.basis.model.surface.control_points, rtol=0, atol=1e-12)
    out = tmp_path / "run"
    run = subprocess.run([sys.executable, "-m", "splinedeform.cli", "run", str(saved), "-o",
                          str(out), "--quiet"], capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr
    assert "outside" not in run.stderr
    report = json.loads((out / "report.json").read_text())
    assert report["probes"]                                   # the grabbed point is a probe
    # saved again: the copy is reused, not copied once more
    _save(session)
    assert sorted(p.name for p in (tmp_path / "out").glob("*grid.npy")) == \
        ["grid.npy", "session-grid.npy"]


@pytest.mark.parametrize("shape", ["plane"])
def test_a_built_in_shape_has_no_path(tmp_path, shape):
    text = SCENARIO.replace('shape = "file"\npath = "grid.npy"', f'shape = "{shape}"')
    (tmp_path / "s.toml").write_text(text)
    session = Session(load_scenario(tmp_path / "s.toml"), resolution=R, modes=None,
                      save_path=tmp_path / "saved.toml")
    assert "path" not in _save(session).read_text().split("[material]")[0]
