"""Sweeps on Dask distributed: equal to the cases run one by one, and nothing lost.

A 2-worker loopback LocalCluster for the module; a worker killed mid-sweep (on its own
cluster), a sweep interrupted by SIGINT and run again, and a scheduler with two workers
started as separate processes (``dask scheduler``, ``dask worker``), all on 127.0.0.1.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

distributed = pytest.importorskip("distributed")

import splinedeform as sd                               # noqa: E402
from splinedeform.pipeline import run                   # noqa: E402
from splinedeform.scenario import parse_scenario        # noqa: E402

from sweep_files import MEMBRANE, write                 # noqa: E402

BIN = Path(sys.executable).parent
LOOPBACK = "127.0.0.1:0"        # the dashboard too listens on the loopback address only
AXES = """\
scenario = "base.toml"

[[axis]]
key = "material.damping"
values = [0.5, 2.0]

[[axis]]
key = "load[1].at"
values = [[0.5, 0.5], [0.3, 0.6], [0.7, 0.2]]
"""


def many(count: int) -> str:
    """A sweep of ``count`` models (one case each): w10 over a range."""
    return f'scenario = "base.toml"\n[[axis]]\nkey = "material.w10"\nrange = [1.0, 4.0]\n' \
           f'count = {count}\n'


@pytest.fixture(scope="module")
def client():
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  host="127.0.0.1", dashboard_address=LOOPBACK) as cluster, \
            distributed.Client(cluster) as c:
        yield c


def stored(out: Path) -> dict[str, tuple[int, int]]:
    """Each stored case file: (inode, mtime); a case computed again gets a new inode."""
    files = [p for p in (out / "cases").glob("*.json") if not p.name.startswith(".")]
    return {p.name: (p.stat().st_ino, p.stat().st_mtime_ns) for p in files}


def test_a_two_worker_sweep_equals_the_cases_run_one_by_one(client, tmp_path):
    result = sd.sweep(write(tmp_path, AXES), tmp_path / "out", client=client)
    assert [row["status"] for row in result.rows] == ["ok"] * 6
    assert result.models == 2 and result.computed == 6       # 6 cases on 2 shared models
    assert "2 solved for 6 cases" in (tmp_path / "out" / "report.md").read_text()
    for row in result.rows:
        damping, at = row["values"]["material.damping"], row["values"]["load[1].at"]
        text = MEMBRANE.replace("damping = 0.5", f"damping = {damping}") \
                       .replace("at = [0.5, 0.5]", f"at = [{at[0]}, {at[1]}]")
        alone = run(parse_scenario(text, source="alone.toml"))
        # the same closed-form modal solution, computed in another process on a model
        # shared with other load cases: equal up to the rounding of reordered BLAS sums
        # (~1e-15 per operation through a dense eigensolve of ~20 unknowns), hence 1e-12
        expected = {"max_displacement": alone.max_displacement,
                    **{f"omega_{i}": w for i, w in enumerate(alone.omegas, start=1)},
                    "kinetic_energy_max": np.max(alone.energy["kinetic"]),
                    "strain_energy_max": np.max(alone.energy["strain"]),
                    "total_energy_end": alone.energy["total"][-1],
                    **{f"p{i}_{c}": h[-1][j] for i, h in enumerate(alone.probes.values(), 1)
                       for j, c in enumerate("xyz")},
                    **{f"p{i}_max": np.linalg.norm(h, axis=-1).max()
                       for i, h in enumerate(alone.probes.values(), 1)}}
        scale = max(abs(alone.max_displacement), 1e-300)
        for name, value in expected.items():
            tol = 1e-12 * (abs(value) if name.startswith(("omega", "kinetic", "strain",
                                                          "total")) else scale)
            assert abs(row[name] - value) <= tol, (row["case"], name, row[name], value)
    assert len({row["worker"] for row in result.rows}) == 2   # both workers took a model


def test_a_failing_case_gets_its_error_and_every_row_is_there_once(client, tmp_path):
    text = AXES.replace("values = [0.5, 2.0]", "values = [0.5, -1.0]")
    result = sd.sweep(write(tmp_path, text), tmp_path / "out", client=client)
    assert [row["case"] for row in result.rows] == [1, 2, 3, 4, 5, 6]
    assert [row["status"] == "ok" for row in result.rows] == [True] * 3 + [False] * 3
    assert "material.damping: expected a number >= 0" in result.rows[3]["status"]
    csv = (tmp_path / "out" / "results.csv").read_text().splitlines()
    assert len(csv) == 7


class KillOnSecondTask(distributed.WorkerPlugin):
    """Kills its worker process when a second sweep task starts on it (once per cluster):
    the first task's cases are stored by then. Writes the stored files at that moment."""

    def __init__(self, marker: str, out: str) -> None:
        self.marker, self.out = marker, out

    def setup(self, worker):
        self.started = 0

    def transition(self, key, start, finish, **kwargs):
        if finish != "executing" or "splinedeform-sweep" not in str(key):
            return
        self.started += 1
        if self.started < 2:
            return
        try:
            fd = os.open(self.marker, os.O_CREAT | os.O_EXCL | os.O_WRONLY)
        except FileExistsError:
            return
        os.write(fd, json.dumps(stored(Path(self.out))).encode())
        os.close(fd)
        os._exit(1)


def test_a_worker_killed_mid_sweep_loses_nothing_and_recomputes_nothing(tmp_path):
    import cloudpickle

    cloudpickle.register_pickle_by_value(sys.modules[__name__])
    out, marker = tmp_path / "out", tmp_path / "killed.json"
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  host="127.0.0.1", dashboard_address=LOOPBACK) as cluster, \
            distributed.Client(cluster) as c:
        c.register_plugin(KillOnSecondTask(str(marker), str(out)))
        result = sd.sweep(write(tmp_path, many(8)), out, client=c)
    assert marker.exists(), "no worker was killed"
    before = {k: tuple(v) for k, v in json.loads(marker.read_text()).items()}
    assert before, "nothing was stored before the kill"
    after = stored(out)
    assert [row["case"] for row in result.rows] == list(range(1, 9))
    assert all(row["status"] == "ok" for row in result.rows)
    assert len(after) == 8
    assert all(after[name] == key for name, key in before.items())    # none computed again


def _sweep_command(*args: str) -> list[str]:
    return [str(BIN / "splinedeform"), "sweep", *args]


def test_a_sweep_interrupted_by_sigint_resumes_with_the_cases_missing(client, tmp_path):
    path, out = write(tmp_path, many(40)), tmp_path / "out"
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    process = subprocess.Popen(_sweep_command(str(path), "-o", str(out), "--workers", "1"),
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                               env=env, start_new_session=True)
    deadline = time.monotonic() + 120
    while len(stored(out)) < 2:
        assert process.poll() is None and time.monotonic() < deadline, process.communicate()
        time.sleep(0.02)
    os.killpg(process.pid, signal.SIGINT)     # as Ctrl-C: the command and its workers
    _, err = process.communicate(timeout=120)
    assert process.returncode == 130, err
    assert "interrupted" in err and "run the same command again" in err
    before = stored(out)
    assert 2 <= len(before) < 40
    result = sd.sweep(path, out, client=client)         # the same sweep, run again
    assert (result.computed, result.reused) == (40 - len(before), len(before))
    after = stored(out)
    assert len(after) == 40 and all(after[name] == key for name, key in before.items())
    csv = (out / "results.csv").read_text().splitlines()[1:]
    assert sorted(int(line.split(",")[0]) for line in csv) == list(range(1, 41))


def test_a_sweep_on_a_scheduler_and_two_workers_started_by_hand(tmp_path):
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    scheduler_file = tmp_path / "scheduler.json"
    started = [subprocess.Popen([str(BIN / "dask"), "scheduler", "--host", "127.0.0.1",
                                 "--port", "0", "--no-dashboard", "--scheduler-file",
                                 str(scheduler_file)], env=env, cwd=tmp_path,
                                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)]
    try:
        deadline = time.monotonic() + 60
        while not scheduler_file.exists():
            assert time.monotonic() < deadline, "the scheduler did not start"
            time.sleep(0.1)
        address = json.loads(scheduler_file.read_text())["address"]
        assert address.startswith("tcp://127.0.0.1:")
        started += [subprocess.Popen([str(BIN / "dask"), "worker", address, "--nthreads", "1",
                                      "--host", "127.0.0.1", "--no-dashboard"], env=env,
                                     cwd=tmp_path, stdout=subprocess.DEVNULL,
                                     stderr=subprocess.DEVNULL) for _ in range(2)]
        with distributed.Client(address, timeout="30s") as c:
            c.wait_for_workers(2, timeout=60)
            workers = set(c.scheduler_info()["workers"])
        out = tmp_path / "out"
        result = sd.sweep(write(tmp_path, AXES), out, scheduler=address)
        assert [row["status"] for row in result.rows] == ["ok"] * 6
        assert {row["worker"] for row in result.rows} <= workers
        assert len(stored(out)) == 6
    finally:
        for process in reversed(started):
            process.terminate()
        for process in started:
            process.wait(timeout=30)
