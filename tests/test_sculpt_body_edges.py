"""A body's boundary edges each with their own preset on the sculpting page, through the
server API as the page drives it: the two flat faces of :mod:`sculpt_body_files` (face 0
``[0, 1] × [0, 1]``, face 1 ``[1, 2] × [0, 1]``, sharing face 0's ``u1`` = face 1's ``u0``)."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("OCP", reason="the body's STEP shell needs OpenCASCADE (the extra 'step')")
from sculpt_body_files import BODY, two_faces  # noqa: E402
from sculpt_client import serve_sheet  # noqa: E402 (skips without the extra)

import splinedeform as sd  # noqa: E402
from splinedeform.body import BodyModel  # noqa: E402
from splinedeform.scenario import load_scenario  # noqa: E402
from splinedeform.sculpt.export import decode  # noqa: E402
from splinedeform.sculpt.messages import PushMessage, SaveMessage  # noqa: E402

pytestmark = pytest.mark.filterwarnings("ignore:Using `httpx`")
R = 6
MATERIAL = {"mass": 1.0, "damping": 2.0, "rayleigh": 0.0, "w10": 1.0, "w01": 1.0,
            "w20": 0.0, "w11": 0.0, "w02": 0.0}
EVERY = {"u0": "clamped", "u1": "clamped", "v0": "clamped", "v1": "clamped"}
#: face 1's far edge and its bottom edge let go, face 0's bottom edge pinned
EDGES = {"1": {"u1": "free", "v0": "free"}, "0": {"v0": "pinned"}}
BOUNDARY = [(0, "u0"), (0, "v0"), (0, "v1"), (1, "u1"), (1, "v0"), (1, "v1")]


@pytest.fixture()
def served(tmp_path):
    faces = two_faces(tmp_path)
    return (*serve_sheet(tmp_path, BODY, resolution=R), faces)


def test_the_page_lists_every_boundary_edge_with_its_preset(served):
    client, _, _ = served
    edges = client.get("/api/basis").json()["body"]["edges"]
    assert [(e["face"], e["edge"]) for e in edges] == BOUNDARY      # the shared edge is none
    assert {e["preset"] for e in edges} == {"clamped"}


def test_a_re_solve_holds_each_edge_by_its_own_preset(served, tmp_path):
    """The modes re-solved with presets per edge are those of the body's model built
    directly with ``{(patch, edge): preset}`` (the constructor's own map, not the page's
    path), and the edges let go move."""
    client, session, faces = served
    reply = client.post("/api/resolve", json={"material": MATERIAL,
                                              "boundary": {**EVERY, "faces": EDGES}})
    assert reply.status_code == 200, reply.text
    data = reply.json()
    presets = {(e["face"], e["edge"]): e["preset"] for e in data["body"]["edges"]}
    assert presets == {(0, "u0"): "clamped", (0, "v0"): "pinned", (0, "v1"): "clamped",
                       (1, "u1"): "free", (1, "v0"): "free", (1, "v1"): "clamped"}
    material = sd.Material(w10=1.0, w01=1.0, damping=2.0)
    # the file's faces read back from STEP: the same nets to 1e-12, so the same modes
    direct = BodyModel(session.basis.patches, material,
                       boundary={(p, e): presets[(p, e)] for p, e in BOUNDARY})
    lam = np.sort(direct.eigen()[0])
    got = decode(data["lam"], "<f8")
    assert got.size == lam.size == direct.n_free
    # two dense eigensolves of the same matrices: 1e-9 of the largest eigenvalue
    assert np.abs(np.sort(got) - lam).max() <= 1e-9 * lam.max()
    # face 1's corner (u, v) = (1, 0) is on two free edges: it moves; face 0's u0 edge is held
    phi = decode(data["phi"]).reshape(2, R, R, -1)
    assert np.abs(phi[1, -1, 0]).max() > 1e-2 * np.abs(phi).max()
    assert np.abs(phi[0, 0]).max() == 0.0                           # no unknown there: exact
    # saved, the scenario names the edges as [boundary.faces]; it reads back the same
    push = PushMessage(index=R * R + 2 * R + 2, force=(0.0, 0.0, -1.0), t_on=0.0, t_off=0.5)
    path, text = session.save(SaveMessage(version=data["version"], t_end=1.0, pushes=[push]))
    assert 'faces = { 1 = { u1 = "free", v0 = "free" }' in text
    assert load_scenario(path).raw["boundary"]["faces"] == EDGES


@pytest.mark.parametrize("faces, words", [
    ({"0": {"u1": "free"}}, "interface"),           # the shared edge takes no condition
    ({"7": {"u0": "free"}}, "face 7 is not in this body"),
    ({"0": {"u0": "pole"}}, "pole"),
])
def test_a_preset_the_body_cannot_take_is_refused_by_its_key(served, faces, words):
    client, session, _ = served
    version = session.version
    reply = client.post("/api/resolve", json={"material": MATERIAL,
                                              "boundary": {**EVERY, "faces": faces}})
    assert reply.status_code == 400 and words in reply.json()["error"], reply.text
    assert session.version == version                               # the basis stays


def test_a_single_surface_refuses_faces(tmp_path):
    from sculpt_client import SHEET

    client, _ = serve_sheet(tmp_path, SHEET, resolution=5)
    reply = client.post("/api/resolve", json={"material": MATERIAL,
                                              "boundary": {**EVERY, "faces": {"0": {"u0": "free"}}}})
    assert reply.status_code == 400 and "one surface" in reply.json()["error"]
