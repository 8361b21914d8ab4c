"""The sculpted shape downloaded from the server (POST /api/export) as .3dm, OBJ and the
project's net JSON: each read back (rhino3dm, the OBJ text, read_control_net) equals the
control net P + T Φ_net q of the modal state sent, computed here in float64."""

from __future__ import annotations

import io
import numpy as np
import pytest

from sculpt_client import serve_sheet  # noqa: E402 (skips without the extra)
import splinedeform as sd  # noqa: E402

pytestmark = pytest.mark.filterwarnings("ignore:Using `httpx`")
SHEET = """
title = "exported sheet"
[surface]
shape = "plane"
cells = [4, 3]
[material]
damping = 1.0
w10 = 1.0
w01 = 1.0
[boundary]
u0 = "clamped"
[solve]
kind = "modes"
"""


@pytest.fixture()
def served(tmp_path):
    return serve_sheet(tmp_path, SHEET, resolution=6)


def _shape(session):
    """A modal state (a static point load's) and its net ``P + d``, float64 here."""
    model = session.basis.model
    d = model.static(sd.Point(0.8, 0.4, (0.1, 0.0, -1.0))).control_points() - model.surface.control_points
    q = session.basis.phi_net.T @ (model.M_full @ d.reshape(-1, 3))
    net = model.surface.control_points + np.asarray(session.basis.phi_net @ q).reshape(d.shape)
    return q, net


def test_the_3dm_download_reads_back_as_the_current_net(served, tmp_path):
    rhino3dm = pytest.importorskip("rhino3dm", reason="the .3dm export needs the extra 'cad'")
    client, session = served
    q, net = _shape(session)
    reply = client.post("/api/export", json={"version": 1, "q": q.ravel().tolist(), "format": "3dm"})
    assert reply.status_code == 200, reply.text
    assert reply.headers["content-disposition"] == 'attachment; filename="exported_sheet-shape.3dm"'
    path = tmp_path / "got.3dm"
    path.write_bytes(reply.content)
    model = rhino3dm.File3dm.Read(str(path))
    assert len(model.Objects) == 1 and model.Objects[0].Attributes.Name == "exported sheet"
    srf = model.Objects[0].Geometry
    got = np.array([[[srf.Points[i, j].X, srf.Points[i, j].Y, srf.Points[i, j].Z]
                     for j in range(srf.Points.CountV)] for i in range(srf.Points.CountU)])
    assert np.abs(net - session.basis.model.surface.control_points).max() > 1e-3   # it moved
    # doubles written and read by openNURBS: 1e-12 of the net's size
    assert got.shape == net.shape and np.max(np.abs(got - net)) <= 1e-12 * np.abs(net).max()


def test_the_obj_and_net_downloads_are_the_current_shape(served, tmp_path):
    from splinedeform.export.nets import read_control_net

    client, session = served
    q, net = _shape(session)
    body = {"version": 1, "q": q.ravel().tolist()}
    obj = client.post("/api/export", json={**body, "format": "obj"})
    assert obj.status_code == 200, obj.text
    vertices = np.loadtxt(io.StringIO("\n".join(line[2:] for line in obj.text.splitlines()
                                                if line.startswith("v "))))
    basis = session.basis
    expect = basis.model.surface.evaluate_grid(basis.samples_u, basis.samples_v,
                                               control_points=net).reshape(-1, 3)
    # %.17g text: read back to the last bit; two evaluations of the same sums, 1e-12
    assert np.max(np.abs(vertices - expect)) <= 1e-12 * np.abs(expect).max()
    doc = client.post("/api/export", json={**body, "format": "json"})
    assert doc.status_code == 200, doc.text
    path = tmp_path / "net.json"
    path.write_bytes(doc.content)
    read = read_control_net(path).control_points
    # repr floats: bit for bit, shown to 1e-15
    assert np.max(np.abs(read - net)) <= 1e-15 * np.abs(net).max()


@pytest.mark.parametrize("body, status", [
    ({"version": 1, "q": [0.0] * 3, "format": "stl"}, 422),        # not a format offered
    ({"version": 1, "q": [0.0] * 5, "format": "obj"}, 400),        # not 3 per mode
    ({"version": 9, "q": [0.0] * 3, "format": "obj"}, 400),        # another basis
])
def test_a_malformed_export_is_refused(served, body, status):
    client, session = served
    reply = client.post("/api/export", json=body)
    assert reply.status_code == status, reply.text
    assert "error" in reply.json()
