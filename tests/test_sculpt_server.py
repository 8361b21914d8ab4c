"""The sculpting server: its JSON endpoints, hostile messages, Save, and the command line."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
import warnings
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("starlette", reason="the sculpt server needs the extra 'sculpt'")
pytest.importorskip("httpx", reason="starlette's TestClient needs httpx")
with warnings.catch_warnings():   # starlette >= 1.0 suggests httpx2; httpx still works
    warnings.simplefilter("ignore")
    from starlette.testclient import TestClient  # noqa: E402

from splinedeform.scenario import parse_scenario  # noqa: E402
from splinedeform.sculpt.export import decode  # noqa: E402
from splinedeform.sculpt.guard import TOKEN_HEADER, Guard  # noqa: E402
from splinedeform.sculpt.server import create_app  # noqa: E402
from splinedeform.sculpt.session import Session  # noqa: E402

SMALL = """
title = "small sheet"
[surface]
shape = "plane"
cells = [5, 4]
[material]
damping = 0.8
w10 = 1.0
w01 = 1.0
w20 = 0.02
w11 = 0.02
w02 = 0.02
[boundary]
u0 = "clamped"
v1 = "pinned"
[solve]
kind = "modes"
"""
RESOLUTION = 7
pytestmark = pytest.mark.filterwarnings("ignore:Using `httpx`")


@pytest.fixture()
def session(tmp_path):
    scenario = parse_scenario(SMALL, source="small.toml", directory=tmp_path)
    return Session(scenario, resolution=RESOLUTION, modes=None,
                   save_path=tmp_path / "saved.toml")


ORIGIN = "http://127.0.0.1:8765"
TOKEN = "test-token"


@pytest.fixture()
def client(session):
    """The page's own requests: addressed to the bound address, same origin, with the token."""
    app = create_app(session, Guard.for_address("127.0.0.1", 8765, TOKEN))
    return TestClient(app, base_url=ORIGIN, raise_server_exceptions=False,
                      headers={"Origin": ORIGIN, TOKEN_HEADER: TOKEN})


GOOD_RESOLVE = {"material": {"mass": 1.0, "damping": 0.5, "rayleigh": 0.0, "w10": 2.0,
                             "w01": 1.0, "w20": 0.02, "w11": 0.02, "w02": 0.02},
                "boundary": {"u0": "clamped", "u1": "clamped", "v0": "free", "v1": "pinned"}}


def test_page_and_basis(client, session):
    page = client.get("/")
    assert page.status_code == 200 and "sculptState" in page.text
    assert "three.js r187" in page.text                      # vendored, inlined: no CDN
    assert "https://" not in page.text.split("<script>", 1)[0]
    data = client.get("/api/basis").json()
    assert data["grid"] == [RESOLUTION, RESOLUTION] and data["version"] == 1
    phi = decode(data["phi"]).reshape(RESOLUTION * RESOLUTION, -1)
    # float32 transport: relative rounding 2**-24 per entry
    assert np.allclose(phi, session.basis.phi_samples, rtol=2**-23, atol=1e-30)


def test_resolve_changes_the_modes(client, session):
    before = session.basis.lam.copy()
    reply = client.post("/api/resolve", json=GOOD_RESOLVE)
    assert reply.status_code == 200, reply.text
    data = reply.json()
    assert data["version"] == 2 and data["material"]["w10"] == 2.0
    assert data["boundary"]["u1"] == "clamped"
    lam = decode(data["lam"], "<f8")
    assert lam.size == session.basis.model.n_free and not np.array_equal(lam[:3], before[:3])
    status = client.get("/api/status").json()
    assert status["busy"] is False and status["stage"] == "done" and status["version"] == 2


def test_resolve_with_a_free_region_moves_only_its_points(client, session):
    """Only control points whose Greville abscissae lie in the box move: fewer free
    coordinates, and the modes vanish at the samples outside the box's support."""
    n_before = session.basis.model.n_free
    body = {**GOOD_RESOLVE, "free_region": {"u": [0.3, 0.7], "v": [0.2, 0.8]}}
    reply = client.post("/api/resolve", json=body)
    assert reply.status_code == 200, reply.status_code
    data = reply.json()
    assert data["free_region"] == {"u": [0.3, 0.7], "v": [0.2, 0.8]}
    assert 0 < data["n_free"] < n_before
    phi = decode(data["phi"]).reshape(RESOLUTION, RESOLUTION, -1)
    assert np.all(phi[0] == 0.0) and np.all(phi[:, 0] == 0.0)    # edges held: exactly zero
    # back to the whole net
    reply = client.post("/api/resolve", json={**GOOD_RESOLVE, "free_region": None})
    assert reply.json()["free_region"] is None and reply.json()["n_free"] > data["n_free"]


def test_the_still_mask_is_where_the_net_cannot_move(client, session):
    """``still_mask`` names the control points no load can move: checked against the static
    displacement under a load on every control point (exactly zero there: they are no
    unknowns; elsewhere the uniform load moves every free point)."""
    from splinedeform import loads

    for body in (None, {**GOOD_RESOLVE, "free_region": {"u": [0.3, 0.7], "v": [0.2, 0.8]}}):
        data = client.post("/api/resolve", json=body).json() if body else \
            client.get("/api/basis").json()
        still = decode(data["still_mask"], "u1").astype(bool)
        model = session.basis.model
        d = model.static(loads.Uniform((0.0, 0.0, -1.0))).control_points() \
            - model.surface.control_points
        assert np.array_equal(still, np.all(d == 0.0, axis=-1).ravel())   # booleans: exact
        nu, nv = model.surface.shape
        grid = still.reshape(nu, nv)
        assert grid[:2].all() and grid[:, -1].all()     # u0 clamped: two rows; v1 pinned
        assert 0 < (~still).sum() == model.n_free


HOSTILE = [
    ("/api/resolve", json.dumps({**GOOD_RESOLVE,
                                 "free_region": {"u": [0.8, 0.2]}}).encode(), 400),
    ("/api/resolve", json.dumps({**GOOD_RESOLVE,
                                 "free_region": {"u": [0.1, None]}}).encode(), 422),
    ("/api/resolve", json.dumps({**GOOD_RESOLVE,
                                 "free_region": {"u": [5.0, 6.0]}}).encode(), 400),
    ("/api/resolve", b"not json", 400),
    ("/api/resolve", b"[1, 2]", 400),
    ("/api/resolve", b"[" * 100000 + b"]" * 100000, 400),          # nesting bomb
    ("/api/resolve", json.dumps({"material": 1}).encode(), 422),
    ("/api/resolve", json.dumps({**GOOD_RESOLVE, "extra": 1}).encode(), 422),
    ("/api/resolve", json.dumps({**GOOD_RESOLVE, "material": {"w10": "NaN"}}).encode(), 422),
    ("/api/resolve", json.dumps({**GOOD_RESOLVE, "material": {"w10": 1e308}}).encode(), 422),
    ("/api/resolve", json.dumps({**GOOD_RESOLVE, "material": {"mass": 0}}).encode(), 422),
    ("/api/resolve", json.dumps({**GOOD_RESOLVE, "material": {"mass": True}}).encode(), 422),
    ("/api/correction", json.dumps({"version": 1, "index": True}).encode(), 422),
    ("/api/resolve", json.dumps({**GOOD_RESOLVE,
                                 "boundary": {"u0": "../../etc/passwd"}}).encode(), 422),
    ("/api/correction", json.dumps({"version": 1, "index": 10**9}).encode(), 400),
    ("/api/correction", json.dumps({"version": 1, "index": -1}).encode(), 422),
    ("/api/correction", json.dumps({"version": 7, "index": 0}).encode(), 400),
    ("/api/save", json.dumps({"version": 1, "t_end": 1.0, "pushes": []}).encode(), 400),
    ("/api/save", json.dumps({"version": 1, "t_end": 1.0, "pushes": [
        {"index": 3, "force": [0, 0, 1e300], "t_on": 0.0}]}).encode(), 422),
    ("/api/save", json.dumps({"version": 1, "t_end": 1.0, "pushes": [
        {"index": 3, "force": [0, 0, 1], "t_on": 0.5, "t_off": 0.2}]}).encode(), 400),
    ("/api/save", json.dumps({"version": 1, "t_end": 1.0, "path": "/tmp/x",
                              "pushes": [{"index": 3, "force": [0, 0, 1], "t_on": 0}]}).encode(),
     422),
    ("/api/save", b"{" + b'"a":1,' * 800000 + b'"b":1}', 413),           # over the size limit
]


@pytest.mark.parametrize("path, body, status", HOSTILE)
def test_hostile_messages_are_refused_and_the_server_lives(client, session, path, body, status):
    reply = client.post(path, content=body, headers={"content-type": "application/json"})
    assert reply.status_code == status, reply.text
    message = reply.json()["error"]
    assert message and "Traceback" not in message
    assert client.get("/api/status").json()["version"] == 1     # still alive, unchanged
    assert not (session.save_path).exists()


def test_physically_refused_resolve_keeps_the_basis(client, session):
    # a free sheet has rigid motions: refused with the scenario's words, basis unchanged
    body = {**GOOD_RESOLVE, "boundary": {"u0": "free", "u1": "free", "v0": "free", "v1": "free"}}
    reply = client.post("/api/resolve", json=body)
    assert reply.status_code == 400 and "rigid" in reply.json()["error"]
    # no stiffness at all: every mode has zero frequency
    zero = {"mass": 1.0, "damping": 0.5}
    reply = client.post("/api/resolve", json={**GOOD_RESOLVE, "material": zero})
    assert reply.status_code == 400, reply.status_code
    assert "error" in reply.json()
    assert client.get("/api/status").json()["version"] == 1
    assert session.progress["busy"] is False


def test_correction_column_is_zero_for_a_complete_basis(client):
    reply = client.post("/api/correction", json={"version": 1, "index": 10})
    assert reply.status_code == 200
    assert np.all(decode(reply.json()["column"]) == 0.0)   # no omitted mode: exactly nothing


def _push_index(i: int, j: int) -> int:
    return i * RESOLUTION + j


def test_save_replays_with_run(client, session, tmp_path):
    """Save writes a scenario whose `splinedeform run` gives the session's numbers: the probes
    of report.json against the page's closed form (the Python twin), to 1e-9 of the largest
    value (both are the complete modal closed form; report.json is written with 17 digits)."""
    from splinedeform.sculpt import Push
    from splinedeform.sculpt.state import modal_history

    pushes = [{"index": _push_index(3, 4), "force": [0.0, 0.0, -1.0], "t_on": 0.0, "t_off": 0.4},
              {"index": _push_index(3, 4), "force": [0.0, 0.3, -1.5], "t_on": 0.4, "t_off": 0.9},
              {"index": _push_index(5, 2), "force": [0.2, 0.0, 0.7], "t_on": 0.6, "t_off": None}]
    reply = client.post("/api/save", json={"version": 1, "t_end": 1.5, "pushes": pushes})
    assert reply.status_code == 200, reply.text
    saved = Path(reply.json()["path"])
    assert saved == session.save_path and saved.is_file()
    out = tmp_path / "out"
    run = subprocess.run([sys.executable, "-m", "splinedeform.cli", "run", str(saved), "-o",
                          str(out), "--quiet"], capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr
    report = json.loads((out / "report.json").read_text())
    probes = report["probes"]
    times = np.asarray(probes["time"], dtype=float)
    basis = session.basis
    ours = [Push(float(basis.samples_u[p["index"] // RESOLUTION]),
                 float(basis.samples_v[p["index"] % RESOLUTION]), tuple(p["force"]), p["t_on"],
                 np.inf if p["t_off"] is None else p["t_off"]) for p in pushes]
    q = modal_history(basis, ours, list(times))
    for name, index in (("p1", _push_index(3, 4)), ("p2", _push_index(5, 2))):
        expect = np.einsum("k,fkc->fc", basis.phi_samples[index], q)
        keys = {c: next(k for k in probes if k.startswith(name + " ") and k.endswith(" d" + c))
                for c in "xyz"}
        got = np.stack([np.asarray(probes[keys[c]], dtype=float) for c in "xyz"], axis=1)
        scale = np.max(np.abs(expect))
        assert scale > 1e-4
        assert np.max(np.abs(got - expect)) <= 1e-9 * scale


def _start(args, cwd):
    env = {**os.environ, "PYTHONUNBUFFERED": "1"}
    proc = subprocess.Popen([sys.executable, "-m", "splinedeform.cli", "sculpt", *args],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=cwd,
                            env=env)
    line = proc.stdout.readline()
    return proc, line


def test_command_serves_and_stops_on_ctrl_c(tmp_path):
    import httpx

    scenario = tmp_path / "small.toml"
    scenario.write_text(SMALL)
    proc, line = _start([str(scenario), "--no-browser", "--resolution", "6"], tmp_path)
    try:
        assert "http://127.0.0.1:" in line, proc.stderr.read() if proc.poll() is not None else line
        url = line.split()[2]
        page = httpx.get(url, timeout=30).text
        token = page.split('name="splinedeform-token" content="', 1)[1].split('"', 1)[0]
        headers = {TOKEN_HEADER: token, "Origin": url.rstrip("/")}
        assert httpx.get(url + "api/status", timeout=30).status_code == 403     # no token
        assert httpx.get(url + "api/status", headers=headers,
                         timeout=30).json()["version"] == 1
        assert httpx.post(url + "api/resolve", content=b"{", headers=headers,
                          timeout=30).status_code == 400
        assert httpx.get(url + "api/status", headers=headers, timeout=30).status_code == 200
        # the running server, as a browser page of another site would reach it
        rebound = {**headers, "Host": "attacker.example:" + url.rstrip("/").rsplit(":", 1)[1]}
        assert httpx.get(url + "api/basis", headers=rebound, timeout=30).status_code == 400
        foreign = {TOKEN_HEADER: token, "Origin": "http://attacker.example",
                   "Content-Type": "text/plain"}
        save = json.dumps({"version": 1, "t_end": 1.0,
                           "pushes": [{"index": 3, "force": [0, 0, 1], "t_on": 0}]})
        assert httpx.post(url + "api/save", content=save, headers=foreign,
                          timeout=30).status_code == 403
        assert not list(tmp_path.glob("*-sculpt.toml"))                 # nothing written
    finally:
        proc.send_signal(signal.SIGINT)
        try:
            code = proc.wait(timeout=20)
        except subprocess.TimeoutExpired:
            proc.kill()
            raise
    err = proc.stderr.read()
    assert code == 0, err
    assert "stopped" in err and "Traceback" not in err


def test_command_refuses_a_taken_port_and_bad_options(tmp_path):
    import socket

    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen(1)
        port = taken.getsockname()[1]
        proc = subprocess.run([sys.executable, "-m", "splinedeform.cli", "sculpt", "--no-browser",
                               "--resolution", "6", "--port", str(port)],
                              capture_output=True, text=True, timeout=120, cwd=tmp_path)
    assert proc.returncode == 2 and f"cannot listen on 127.0.0.1:{port}" in proc.stderr
    proc = subprocess.run([sys.executable, "-m", "splinedeform.cli", "sculpt", "--no-browser",
                           "--modes", "0"], capture_output=True, text=True, timeout=120,
                          cwd=tmp_path)
    assert proc.returncode == 2 and "--modes" in proc.stderr
