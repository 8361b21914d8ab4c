"""A run owns its output folder: stale files, temporaries, the manifest, killed runs."""

from __future__ import annotations

import json
import signal
import subprocess
import sys
import time
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

from splinedeform import InputError
from splinedeform.export import claim_folder, file_digest, manifest_name
from splinedeform.pipeline import run, summary_rows
from splinedeform.scenario import parse_scenario

meshio = pytest.importorskip("meshio")

SCENARIO = """\
[surface]
shape = "plane"
cells = 4

[material]
mass = 1.0
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
frames = {frames}

[output]
formats = {formats}
resolution = 6
"""


def scenario(frames: int = 6, formats: str = '["vtu", "json", "npz", "report", "obj"]'):
    return parse_scenario(SCENARIO.format(frames=frames, formats=formats), source="case.toml")


def manifest(folder: Path) -> dict:
    return json.loads((folder / manifest_name("case")).read_text())


def assert_consistent(folder: Path) -> None:
    """Complete manifest, every listed file present with its size and hash, no temporaries,
    and the .pvd lists exactly the .vtu files there are."""
    doc = manifest(folder)
    assert doc["complete"] is True
    listed = {f["name"]: f for f in doc["files"]}
    for name, entry in listed.items():
        assert file_digest(folder / name) == (entry["bytes"], entry["sha256"])
    assert [p.name for p in folder.iterdir() if p.name.startswith(".")] == []
    present = sorted(p.name for p in folder.iterdir())
    assert present == sorted([*listed, manifest_name("case")])
    if (folder / "case.pvd").exists():
        pvd = [d.get("file") for d in ET.parse(folder / "case.pvd").getroot().iter("DataSet")]
        assert sorted(pvd) == sorted(n for n in present if n.endswith(".vtu"))


def test_a_rerun_with_fewer_frames_removes_the_stale_frames_and_says_so(tmp_path):
    first = run(scenario(frames=8), tmp_path)
    assert_consistent(tmp_path)
    assert len(list(tmp_path.glob("case_*.vtu"))) == 8
    second = run(scenario(frames=3), tmp_path)
    assert_consistent(tmp_path)
    assert sorted(p.name for p in second.removed) == [f"case_{i:04d}.vtu" for i in range(3, 8)]
    rows = dict((label, value) for label, value in summary_rows(second) if label == "removed")
    assert rows["removed"] == "5 file(s) left by an earlier run of this scenario: " \
        "case_0003.vtu, case_0004.vtu, case_0005.vtu, case_0006.vtu, case_0007.vtu"
    run(scenario(frames=12), tmp_path)
    third = run(scenario(frames=2), tmp_path)
    rows = dict((label, value) for label, value in summary_rows(third) if label == "removed")
    assert rows["removed"] == "10 file(s) left by an earlier run of this scenario: " \
        "case_0002.vtu, case_0003.vtu, case_0004.vtu, …, case_0011.vtu"
    assert first.removed == []


def test_a_rerun_without_a_format_removes_its_files(tmp_path):
    run(scenario(), tmp_path)
    second = run(scenario(formats='["report"]'), tmp_path)
    assert_consistent(tmp_path)
    assert sorted(p.name for p in tmp_path.iterdir()) == \
        sorted(["report.json", "report.md", manifest_name("case")])
    assert "case_nets.npz" in {p.name for p in second.removed}


def test_files_the_run_did_not_create_are_never_deleted(tmp_path):
    (tmp_path / "case_nets.npz").write_bytes(b"the user's own file")
    (tmp_path / "case_0042.vtu").write_text("from somewhere else")
    (tmp_path / "notes.txt").write_text("mine")
    result = run(scenario(formats='["json", "vtu"]'), tmp_path)
    assert (tmp_path / "case_nets.npz").read_bytes() == b"the user's own file"
    assert (tmp_path / "notes.txt").read_text() == "mine"
    assert (tmp_path / "case_0042.vtu").exists()
    assert [(p.name, "no run recorded it" in why) for p, why in result.kept] == \
        [("case_0042.vtu", True)]
    # a file of ours changed by hand after the run is kept too, and reported
    (tmp_path / "case_0005.vtu").write_text("edited")
    again = run(scenario(frames=3, formats='["json", "vtu"]'), tmp_path)
    assert (tmp_path / "case_0005.vtu").read_text() == "edited"
    assert ("case_0005.vtu", "changed since an earlier run wrote it") in \
        [(p.name, why) for p, why in again.kept]
    assert (tmp_path / "case_0004.vtu").exists() is False


def test_stale_temporaries_of_our_files_are_removed_and_others_kept(tmp_path):
    run(scenario(), tmp_path)
    ours = [tmp_path / ".case_0001.0123456789ab.tmp.vtu", tmp_path / ".report.abcdefabcdef.tmp.json"]
    theirs = [tmp_path / ".notes.0123456789ab.tmp.txt", tmp_path / ".case_0001.vtu.swp"]
    for path in ours + theirs:
        path.write_text("left by a killed process")
    result = run(scenario(), tmp_path)
    assert all(not p.exists() for p in ours) and all(p.exists() for p in theirs)
    assert sorted(result.removed) == sorted(ours)


def test_a_foreign_manifest_is_refused_and_left_alone(tmp_path):
    (tmp_path / manifest_name("case")).write_text('{"my": "own data"}')
    with pytest.raises(InputError, match="not a splinedeform run manifest"):
        run(scenario(), tmp_path)
    assert json.loads((tmp_path / manifest_name("case")).read_text()) == {"my": "own data"}


def test_a_second_run_into_a_locked_folder_is_refused(tmp_path):
    claim = claim_folder(tmp_path, "other", [])
    try:
        with pytest.raises(InputError, match="another splinedeform run is writing"):
            run(scenario(), tmp_path)
    finally:
        claim.release()
    assert not (tmp_path / manifest_name("case")).exists()      # refused before writing
    run(scenario(), tmp_path)
    assert manifest(tmp_path)["complete"] is True


def test_another_scenarios_files_stay(tmp_path):
    run(scenario(), tmp_path)
    other = parse_scenario(SCENARIO.format(frames=4, formats='["vtu", "report"]'),
                           source="other.toml")
    run(other, tmp_path)
    run(scenario(formats='["json"]'), tmp_path)        # case no longer writes vtu or report
    assert len(list(tmp_path.glob("other_*.vtu"))) == 4
    assert (tmp_path / "report.json").exists()          # other's manifest lists it


def readable(path: Path) -> None:
    """Raise if a file under a final name is not whole."""
    if path.suffix in (".vtu", ".obj"):
        meshio.read(path)
    elif path.suffix == ".json":
        json.loads(path.read_text())
    elif path.suffix == ".npz":
        with np.load(path) as z:
            [z[k] for k in z.files]
    elif path.suffix in (".pvd",):
        ET.parse(path)
    elif path.suffix == ".md":
        assert path.read_text().startswith("# ")
    else:
        raise AssertionError(f"unexpected file {path.name}")


RUNNER = """
import sys
from splinedeform.pipeline import run
from splinedeform.scenario import parse_scenario
run(parse_scenario(open(sys.argv[1]).read(), source="case.toml"), sys.argv[2])
"""


def inode(path: Path) -> int | None:
    try:
        return path.stat().st_ino
    except FileNotFoundError:
        return None


def start_writing_run(command: list[str], folder: Path) -> tuple[subprocess.Popen, float]:
    """Start a run and wait until it has claimed the folder: a new manifest (atomic
    replace, so a new inode) that says incomplete. Returns the process and that time."""
    path = folder / manifest_name("case")
    before = inode(path)
    process = subprocess.Popen(command)
    while process.poll() is None:
        try:
            if inode(path) != before and json.loads(path.read_text())["complete"] is False:
                return process, time.monotonic()
        except (FileNotFoundError, json.JSONDecodeError):
            pass
        time.sleep(0.002)
    raise AssertionError(f"the run ended (exit {process.returncode}) before it wrote anything")


def test_a_run_killed_at_random_moments_leaves_whole_files_and_the_next_run_cleans_up(tmp_path):
    """SIGKILL at seeded random moments while a run writes its files.

    The first run is whole; it measures how long writing takes. Each later run is killed
    at a moment drawn uniformly over that span after it claimed the folder. Afterwards every
    file under a final name must read as a whole file, and the manifest must either say
    incomplete or match the files; a final run with fewer frames leaves a consistent set.
    """
    folder = tmp_path / "out"
    folder.mkdir()
    big = tmp_path / "case.toml"
    big.write_text(SCENARIO.format(frames=200, formats='["vtu", "json", "npz", "report", "obj"]'))
    command = [sys.executable, "-c", RUNNER, str(big), str(folder)]
    subprocess.run(command, check=True, timeout=300)
    process, began = start_writing_run(command, folder)
    assert process.wait(timeout=300) == 0
    span = time.monotonic() - began
    rng = np.random.default_rng(2026)
    incomplete = 0
    for moment in rng.uniform(0.0, 1.0, 5) * span:
        process, began = start_writing_run(command, folder)
        time.sleep(max(0.0, began + moment - time.monotonic()))
        process.send_signal(signal.SIGKILL)
        process.wait(timeout=60)
        for path in folder.iterdir():
            if not path.name.startswith("."):
                readable(path)                      # no partial file under a final name
        doc = manifest(folder)
        incomplete += not doc["complete"]
        if doc["complete"]:                        # killed after the manifest: all whole
            assert_consistent(folder)
    assert incomplete >= 1                          # at least one kill hit the writing
    small = tmp_path / "small.toml"
    small.write_text(SCENARIO.format(frames=5, formats='["vtu", "json", "report"]'))
    subprocess.run([sys.executable, "-c", RUNNER, str(small), str(folder)], check=True,
                   timeout=300)
    assert_consistent(folder)
    assert len(list(folder.glob("*.vtu"))) == 5


def test_the_command_line_says_what_it_removed(tmp_path):
    typer_testing = pytest.importorskip("typer.testing")
    from splinedeform import cli

    path = tmp_path / "case.toml"
    out = tmp_path / "out"
    runner = typer_testing.CliRunner()
    for frames in (5, 2):
        path.write_text(SCENARIO.format(frames=frames, formats='["vtu"]'))
        result = runner.invoke(cli.app, ["run", str(path), "-o", str(out)])
        assert result.exit_code == 0, result.output
    text = " ".join(result.stdout.split())          # the table may wrap long cells
    assert "removed" in text and "3 file(s) left by an earlier run" in text
    for name in ("case_0002.vtu", "case_0003.vtu", "case_0004.vtu"):
        assert name in text
