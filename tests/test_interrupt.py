"""Ctrl-C during ``splinedeform run``: one line saying where the run stopped, what it left
incomplete and that running the same command again cleans it up; exit status 130.

The runs are subprocesses that get a real SIGINT: from themselves at a chosen moment of
writing (so the moment is exact), or from this process while they solve.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
from pathlib import Path

import pytest

from splinedeform.export import manifest_name

pytest.importorskip("meshio")

SCENARIO = """\
[surface]
shape = "plane"
cells = 3

[material]
damping = 0.5
w10 = 1.0
w01 = 1.0

[boundary]
u0 = "clamped"
u1 = "clamped"

[[load]]
kind = "uniform"
force = [0.0, 0.0, -1.0]

[solve]
kind = "dynamic"
t_end = 1.0
frames = 5

[output]
formats = ["vtu", "report"]
resolution = 4
"""

#: runs the command line after arranging a SIGINT: "write" — to itself as the third frame
#: of the time series is about to be written; "solve" — says "solving" and waits in the solve
RUNNER = """\
import os, signal, sys, time
import splinedeform.export.series as series
import splinedeform.model as model
from splinedeform import cli

when = sys.argv[1]
if when == "write":
    calls, write_mesh = [], series.write_mesh
    def interrupted_mesh(*args, **kwargs):
        calls.append(1)
        if len(calls) == 3:
            os.kill(os.getpid(), signal.SIGINT)
        return write_mesh(*args, **kwargs)
    series.write_mesh = interrupted_mesh
elif when == "solve":
    def waiting(*args, **kwargs):
        print("solving", flush=True)
        time.sleep(60)
    model.Model.dynamic = waiting
sys.argv = ["splinedeform", "run", *sys.argv[2:]]
cli.main()
"""


def run_cli(*args: str, when: str = "never", **popen: object) -> subprocess.Popen:
    env = {**os.environ, "MPLBACKEND": "Agg"}
    return subprocess.Popen([sys.executable, "-c", RUNNER, when, *args], env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, **popen)


def interrupted_lines(stderr: str) -> list[str]:
    return [line for line in stderr.splitlines() if "interrupted" in line]


def test_ctrl_c_while_writing_says_what_is_incomplete_and_a_rerun_cleans_up(tmp_path):
    case, out = tmp_path / "case.toml", tmp_path / "out"
    case.write_text(SCENARIO)
    process = run_cli(str(case), "-o", str(out), when="write")
    _, stderr = process.communicate(timeout=120)
    assert process.returncode == 130, stderr
    lines = interrupted_lines(stderr)
    assert len(lines) == 1, stderr
    # the series of 5 frames, its .pvd and the two reports: 8 files, 2 frames written
    assert lines[0].startswith("interrupted during time series: ")
    assert f"{out / manifest_name('case')} is marked incomplete (2 of 8 files there; " \
           "missing case_0002.vtu, case_0003.vtu, case_0004.vtu and 3 more)" in lines[0]
    assert lines[0].endswith("run the same command again to clean it up and write the "
                             "whole set")
    assert "Traceback" not in stderr
    assert json.loads((out / manifest_name("case")).read_text())["complete"] is False
    again = run_cli(str(case), "-o", str(out), "--quiet")
    _, stderr = again.communicate(timeout=120)
    assert again.returncode == 0, stderr
    doc = json.loads((out / manifest_name("case")).read_text())
    assert doc["complete"] is True and len(doc["files"]) == 8
    assert sorted(p.name for p in out.iterdir()) == sorted(
        [f["name"] for f in doc["files"]] + [manifest_name("case")])


def test_ctrl_c_while_solving_says_nothing_was_written(tmp_path):
    case, out = tmp_path / "case.toml", tmp_path / "out"
    case.write_text(SCENARIO)
    process = run_cli(str(case), "-o", str(out), "--quiet", when="solve")
    assert process.stdout.readline() == "solving\n"
    process.send_signal(signal.SIGINT)                        # what Ctrl-C sends
    _, stderr = process.communicate(timeout=60)
    assert process.returncode == 130, stderr
    assert interrupted_lines(stderr) == [
        f"interrupted during solve: no output of this run was written in {out}"]
    assert not (out / manifest_name("case")).exists()
