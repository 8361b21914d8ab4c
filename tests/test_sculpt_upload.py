"""A surface loaded from the page (POST /api/load): a net file, a .3dm and a scenario each
become the surface the modes are solved on (its control net read back exactly); wrong
kinds, empty, oversized and malformed files are refused with the file's name (and, for a
scenario, its line), leaving the session and the folder as they were."""

from __future__ import annotations

import numpy as np
import pytest

from sculpt_client import SHEET, serve_sheet  # noqa: E402 (skips without the extra)
import splinedeform as sd  # noqa: E402
from splinedeform.sculpt.guard import TOKEN_HEADER  # noqa: E402
from splinedeform.export.nets import write_control_nets  # noqa: E402
from splinedeform.sculpt.upload import MAX_UPLOAD  # noqa: E402

pytestmark = pytest.mark.filterwarnings("ignore:Using `httpx`")


@pytest.fixture()
def served(tmp_path):
    return serve_sheet(tmp_path)


def _send(client, name, content, **headers):
    return client.post("/api/load", content=content,
                       headers={"X-Sculpt-File-Name": name, "Content-Type": "application/octet-stream",
                                **headers})


def _bent(cells=(4, 2)):
    surf = sd.shapes.plane(size=(2.0, 1.0), cells=cells)
    P = surf.control_points.copy()
    P[..., 2] = 0.1 * np.sin(P[..., 0]) * P[..., 1]        # not a flat net
    return surf, P


def test_a_net_file_becomes_the_surface(served, tmp_path):
    client, session = served
    surf, P = _bent()
    path, = write_control_nets(tmp_path / "..", "elsewhere", surf, [0.0], P[None], formats=("json",))
    reply = _send(client, "my net.json", path.read_bytes())
    assert reply.status_code == 200, reply.text
    data = reply.json()
    assert data["loaded"] == "my net.json" and data["version"] == 2 and data.get("carry") is None
    got = session.basis.model.surface.control_points
    # repr floats: read back bit for bit, shown to 1e-15
    assert got.shape == P.shape and np.max(np.abs(got - P)) <= 1e-15 * np.abs(P).max()
    assert session.scenario.boundary.u0 == "clamped"      # material and boundary stay
    assert (tmp_path / "saved-loaded-2.json").exists()     # beside the save, for Save
    assert client.post("/api/undo", json={"version": 2}).json() == {"version": 1}
    assert session.basis.model.surface.shape == (6, 6)


def test_a_3dm_file_becomes_the_surface(served, tmp_path):
    pytest.importorskip("rhino3dm", reason="reading .3dm files needs the extra 'cad'")
    from splinedeform.cad import patch_from_surface, write_3dm

    client, session = served
    surf, P = _bent((3, 3))
    path = write_3dm(tmp_path / "in.3dm", [patch_from_surface(surf, P)])
    reply = _send(client, "part.3dm", path.read_bytes())
    assert reply.status_code == 200, reply.text
    got = session.basis.model.surface.control_points
    # doubles through openNURBS: 1e-12 of the net's size
    assert np.max(np.abs(got - P)) <= 1e-12 * np.abs(P).max()


def test_a_scenario_becomes_the_session(served):
    client, session = served
    text = SHEET.replace("cells = 3", "cells = 4").replace('u0 = "clamped"', 'v1 = "pinned"')
    reply = _send(client, "other.toml", text.encode())
    assert reply.status_code == 200, reply.text
    assert session.basis.model.surface.shape == (7, 7)
    assert session.scenario.boundary.v1 == "pinned" and session.scenario.boundary.u0 == "free"


@pytest.mark.parametrize("name, content, status, words", [
    ("shape.stl", b"solid", 400, "shape.stl: cannot load this kind of file"),
    ("net.json", b"", 400, "net.json: the file is empty"),
    ("net.json", b"{not json", 400, "net.json"),
    ("bad.toml", b"[surface]\nshape = \"plane\"\ncells = -2\n", 400, "bad.toml:3"),
    ("bad.toml", b"\xff\xfe", 400, "bad.toml: not UTF-8"),
    ("../up.json", b"{}", 400, "no folders"),
])
def test_a_bad_file_is_refused_by_name_and_changes_nothing(served, tmp_path, name, content, status, words):
    client, session = served
    reply = _send(client, name, content)
    assert reply.status_code == status, reply.text
    assert words in reply.json()["error"], reply.json()["error"]
    assert session.version == 1 and session.scenario.surface.shape == "plane"
    assert not list(tmp_path.glob("saved-loaded-*"))


def test_an_oversized_or_unguarded_load_is_refused(served, tmp_path):
    client, session = served
    reply = _send(client, "big.json", b"x", **{"Content-Length": str(MAX_UPLOAD + 1)})
    assert reply.status_code == 413 and "big.json" in reply.json()["error"]
    reply = client.post("/api/load", content=b"{}", headers={"X-Sculpt-File-Name": "a.json",
                                                              TOKEN_HEADER: "wrong"})
    assert reply.status_code == 403
    assert session.version == 1 and not list(tmp_path.glob("saved-loaded-*"))
