"""A ``pole`` edge must be collapsed: its control points coincide, or it is refused.

The flat rectangle ``[0, 2] × [0, 1]`` (open knots, linear precision) has straight edges:
the control polygon of ``u0`` (along v) is exactly 1 long, that of ``v0`` (along u) 2, and
the net's size, its bounding-box diagonal, is √5. The library, ``splinedeform validate``
and the sculpting server refuse them with those numbers; a half sphere's pole passes.
"""

from __future__ import annotations

import math
import subprocess
import sys
import warnings

import numpy as np
import pytest

import splinedeform as sd
from splinedeform.boundary import POLE_TOLERANCE, check_poles
from splinedeform.errors import InputError

MATERIAL = sd.Material(w10=1.0, w01=1.0)


@pytest.mark.parametrize("edge, length", [("u0", 1.0), ("u1", 1.0), ("v0", 2.0), ("v1", 2.0)])
def test_a_straight_edge_is_no_pole(edge, length):
    plate = sd.shapes.plane(size=(2.0, 1.0), cells=3)
    with pytest.raises(InputError) as info:
        sd.Model(plate, MATERIAL, boundary={edge: "pole", "u0" if edge != "u0" else "u1":
                                            "clamped"})
    message = str(info.value)
    assert f"boundary.{edge} = 'pole'" in message
    # the polygon of the straight edge and the diagonal are closed forms, printed to 6 digits
    assert f"is {length:.6g} long" in message and f"size {math.sqrt(5.0):.6g}" in message
    assert getattr(info.value, "key", None) == f"boundary.{edge}"


def test_a_collapsed_edge_passes_and_a_spread_one_is_measured():
    sphere = sd.shapes.half_sphere(cells=(8, 3))
    sd.Model(sphere, MATERIAL, boundary={"v0": "clamped", "v1": "pole"})     # its pole
    net = sphere.control_points.copy()
    size = np.linalg.norm(net.max(axis=(0, 1)) - net.min(axis=(0, 1)))
    net[3, -1, 0] += 10 * POLE_TOLERANCE * size         # one pole point moved off the pole
    with pytest.raises(InputError, match="boundary.v1"):
        check_poles({"v1": "pole"}, net)
    net[3, -1, 0] -= 9.5 * POLE_TOLERANCE * size        # within the tolerance: round-off
    check_poles({"v1": "pole"}, net)


PLATE = """
[surface]
shape = "plane"
cells = 3
[material]
w10 = 1.0
w01 = 1.0
[boundary]
u0 = "clamped"
v1 = "pole"
[solve]
kind = "modes"
"""


def test_validate_refuses_it_at_the_line_of_the_edge(tmp_path):
    path = tmp_path / "plate.toml"
    path.write_text(PLATE)
    line = PLATE.splitlines().index('v1 = "pole"') + 1
    run = subprocess.run([sys.executable, "-m", "splinedeform.cli", "validate", str(path)],
                         capture_output=True, text=True, timeout=120)
    assert run.returncode == 2, run.stdout + run.stderr
    assert f"{path}:{line}: boundary.v1" in run.stderr and "collapsed edge" in run.stderr
    assert "Traceback" not in run.stderr


def test_the_sculpting_server_refuses_it_and_keeps_its_basis(tmp_path):
    pytest.importorskip("starlette", reason="the sculpt server needs the extra 'sculpt'")
    pytest.importorskip("httpx", reason="starlette's TestClient needs httpx")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        from starlette.testclient import TestClient
    from splinedeform.scenario import parse_scenario
    from splinedeform.sculpt.guard import TOKEN_HEADER, Guard
    from splinedeform.sculpt.server import create_app
    from splinedeform.sculpt.session import Session

    text = PLATE.replace('v1 = "pole"', "")
    session = Session(parse_scenario(text, source="plate.toml", directory=tmp_path),
                      resolution=4, modes=None, save_path=tmp_path / "saved.toml")
    origin = "http://127.0.0.1:8765"
    client = TestClient(create_app(session, Guard.for_address("127.0.0.1", 8765, "t")),
                        base_url=origin, headers={"Origin": origin, TOKEN_HEADER: "t"})
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        reply = client.post("/api/resolve", json={
            "material": {"mass": 1.0, "w10": 1.0, "w01": 1.0},
            "boundary": {"u0": "clamped", "u1": "free", "v0": "free", "v1": "pole"}})
    assert reply.status_code == 400
    assert "boundary.v1" in reply.json()["error"] and "collapsed edge" in reply.json()["error"]
    assert session.version == 1
