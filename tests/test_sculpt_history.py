"""Bake (the current shape becomes the rest shape) and undo/redo on the sculpting server.

The baked net is checked against a closed form of the model: the static displacement under
a point load, expressed in the (complete) modes, ``q = Φᵀ T_r-reduced M d``; baked, the
new surface's control net is ``P + d``. Undo and redo switch back to the very basis kept.
"""

from __future__ import annotations

import numpy as np
import pytest

from sculpt_client import SHEET, serve_sheet  # noqa: E402 (skips without the extra)
import splinedeform as sd  # noqa: E402
from splinedeform.scenario import build, load_scenario, parse_scenario  # noqa: E402
from splinedeform.sculpt.export import decode  # noqa: E402

pytestmark = pytest.mark.filterwarnings("ignore:Using `httpx`")


@pytest.fixture()
def served(tmp_path):
    return serve_sheet(tmp_path)


def _static_state(session):
    """``d`` of a static point load and its modal coordinates ``q = Φ_netᵀ M d`` (every mode
    kept, mass-orthonormal: exact to rounding)."""
    model = session.basis.model
    d = model.static(sd.Point(0.7, 0.4, (0.0, 0.1, -1.0))).control_points() \
        - model.surface.control_points
    q = session.basis.phi_net.T @ (model.M_full @ d.reshape(-1, 3))
    return d, q


def test_bake_makes_the_shape_the_rest_shape_and_undo_redo_switch_exactly(served, tmp_path):
    client, session = served
    first = session.basis
    d, q = _static_state(session)

    reply = client.post("/api/bake", json={"version": 1, "q": q.ravel().tolist()})
    assert reply.status_code == 200, reply.text
    data = reply.json()
    assert data["baked"] and data["version"] == 2 and data["carry"]["from_version"] == 1
    second = session.basis
    baked = second.model.surface.control_points
    # P + d: d from a sparse solve, its modal round trip to ~1e-13 of |d| (condition of M)
    assert np.abs(d).max() > 1e-3
    assert np.max(np.abs(baked - first.model.surface.control_points - d)) <= 1e-10 * np.abs(d).max()
    # the page's rest samples are the baked surface's (float32 transport: 2^-24 relative)
    rest = decode(data["rest"]).reshape(-1, 3)
    uu, vv = np.meshgrid(session.basis.samples_u, session.basis.samples_v, indexing="ij")
    surface = session.basis.model.surface
    assert np.allclose(rest, surface.evaluate(uu.ravel(), vv.ravel()), rtol=0, atol=1e-6)
    # the baked shape is a control-net file beside the save, and Save names it relative
    assert session.scenario.surface.shape == "file"
    path = session.scenario.surface.path
    assert path.parent == tmp_path.resolve() and path.name == "saved-baked-2.json"
    push = {"index": 12, "force": [0.0, 0.0, -1.0], "t_on": 0.0, "t_off": 0.5}
    assert client.post("/api/save", json={"version": 2, "t_end": 1.0,
                                          "pushes": [push]}).status_code == 200
    replay = build(load_scenario(session.save_path)).surface.control_points
    # the net file holds floats written with repr: read back to the last bit (1e-15 shown)
    assert np.max(np.abs(replay - baked)) <= 1e-15 * np.abs(baked).max()
    # undo: the very basis before, under its version; redo: the baked one
    assert client.post("/api/undo", json={"version": 2}).json() == {"version": 1}
    assert session.basis is first and session.version == 1
    assert client.post("/api/undo", json={"version": 1}).status_code == 400   # nothing left
    assert client.post("/api/redo", json={"version": 2}).status_code == 400   # not shown
    assert client.post("/api/redo", json={"version": 1}).json() == {"version": 2}
    assert session.basis is second and session.version == 2
    assert client.get("/api/status").json()["version"] == 2


def test_a_new_change_after_undo_drops_the_redo_and_versions_stay_unique(served):
    client, session = served
    _, q = _static_state(session)
    client.post("/api/bake", json={"version": 1, "q": q.ravel().tolist()})
    client.post("/api/undo", json={"version": 2})
    body = {"material": {"mass": 1.0, "damping": 1.0, "w10": 2.0, "w01": 1.0},
            "boundary": {"u0": "clamped"}}
    assert client.post("/api/resolve", json=body).json()["version"] == 3    # never 2 again
    assert client.post("/api/redo", json={"version": 3}).status_code == 400
    assert client.post("/api/undo", json={"version": 3}).json() == {"version": 1}


@pytest.mark.parametrize("body, status", [
    ({"version": 1, "q": [0.0] * 5}, 400),              # not 3 per mode
    ({"version": 7, "q": [0.0] * 3}, 400),              # another basis
    ({"version": 1, "q": [True, 0.0, 0.0]}, 422),
    ({"version": 1, "q": []}, 422),
])
def test_a_malformed_bake_is_refused_and_changes_nothing(served, body, status):
    client, session = served
    reply = client.post("/api/bake", json=body)
    assert reply.status_code == status, reply.text
    assert session.version == 1 and session.scenario.surface.shape == "plane"


def test_a_pin_bakes_and_holds_the_control_point_where_the_bake_put_it(served):
    """A pin is a bake with the free set less one control point: that point is at P + d
    (the shape at the pin) and a push elsewhere no longer moves it at all."""
    client, session = served
    d, q = _static_state(session)
    nu, nv = session.basis.model.surface.shape
    pinned = (2, 3)
    free = [[i, j] for i in range(nu) for j in range(nv) if (i, j) != pinned]
    reply = client.post("/api/bake", json={"version": 1, "q": q.ravel().tolist(), "free_points": free})
    assert reply.status_code == 200, reply.text
    model = session.basis.model
    start = build(parse_scenario(SHEET, source="sheet.toml")).surface.control_points
    # where the pin put it: P + d, d a sparse solve through its modal round trip (as above)
    assert np.abs(d[pinned]).max() > 1e-3
    assert np.max(np.abs(model.surface.control_points[pinned] - start[pinned] - d[pinned])) \
        <= 1e-10 * np.abs(d).max()
    # a push at another point moves the net but not the pinned point: its row of T is empty
    moved = model.static(sd.Point(0.3, 0.6, (0.2, 0.0, -1.0))).control_points() \
        - model.surface.control_points
    assert np.abs(moved).max() > 1e-3
    assert np.abs(moved[pinned]).max() == 0.0      # held exactly: no coordinate maps to it
    assert session.scenario.boundary.free_points is not None
    assert tuple(pinned) not in session.scenario.boundary.free_points


def test_a_pin_outside_the_net_is_refused_and_changes_nothing(served):
    client, session = served
    _, q = _static_state(session)
    reply = client.post("/api/bake", json={"version": 1, "q": q.ravel().tolist(),
                                           "free_points": [[0, 0], [40, 1]]})
    assert reply.status_code == 400, reply.text
    assert "Free set" in reply.json()["error"]
    assert session.version == 1 and session.scenario.surface.shape == "plane"
    assert not list(session.save_path.parent.glob("*baked*"))
