"""A pin (alt-click) on a body in the sculpting page, through the server API as the page
drives it: a bake whose message carries the body's painted set less the pinned point as
``faces_free_points`` (sculpt/body_paint.py, ``Session.bake``). The body is the two flat
faces of :mod:`sculpt_body_files` (face 0 ``[0, 1] × [0, 1]``, face 1 ``[1, 2] × [0, 1]``,
cubic 6 × 6 nets, face 0's row 5 = face 1's row 0), every boundary edge clamped, so face
0's moving points are rows 2 .. 5 of columns 2, 3.

A fixed control point is no unknown: its row of the constraint map ``T`` is empty, so its
row of every mode ``T Φ`` is an empty sum, exactly 0; the tests allow 1e-14 of the largest
entry (the bound of :mod:`test_sculpt_body_paint`), far below the 1e-3 of a point a mode
moves.
"""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("OCP", reason="the body's STEP shell needs OpenCASCADE (the extra 'step')")
from sculpt_body_files import BODY, two_faces  # noqa: E402
from sculpt_client import SHEET, serve_sheet  # noqa: E402 (skips without the extra)
from test_sculpt_body_paint import (MOVES, ZERO, face_rows, run_saved,  # noqa: E402
                                    three_strips)

from splinedeform.scenario import load_scenario  # noqa: E402
from splinedeform.sculpt.export import decode  # noqa: E402
from splinedeform.sculpt.messages import PushMessage, SaveMessage  # noqa: E402

pytestmark = pytest.mark.filterwarnings("ignore:Using `httpx`")
R = 6
N = 6                                   # each face's net: 3 cubic spans, 6 × 6 points
PIN = (3, 2)                            # an interior point of face 0
SHARED = (5, 3)                         # on face 0's u1 edge: face 1's (0, 3)


def every_point_but(*pinned):
    """Face ``0``'s whole net less ``pinned``, as the page sends it (``[i, j]``)."""
    return [[i, j] for i in range(N) for j in range(N) if (i, j) not in pinned]


@pytest.fixture()
def served(tmp_path):
    two_faces(tmp_path)
    return serve_sheet(tmp_path, BODY, resolution=R)


def small_shape(session):
    """A modal state ``q`` to bake: mode 1 lifted (z) a little."""
    q = np.zeros(3 * session.basis.lam.size)
    q[2] = 1e-2
    return q


def pin(client, session, faces):
    version = session.version
    return client.post("/api/bake", json={"version": version, "q": small_shape(session).tolist(),
                                          "faces_free_points": faces})


def test_a_pin_fixes_the_point_where_the_bake_put_it_and_the_rest_still_moves(served):
    client, session = served
    q = small_shape(session)
    before = session.basis
    shape = before.rest_net() + before.phi_net @ q.reshape(-1, 3)     # the shape baked
    row = PIN[0] * N + PIN[1]
    assert np.abs(before.phi_net[row]).max() > MOVES * np.abs(before.phi_net).max()
    reply = pin(client, session, {"0": every_point_but(PIN)})
    assert reply.status_code == 200, reply.text
    data = reply.json()
    assert data["baked"] and data["version"] == 2
    basis = session.basis
    top = np.abs(basis.phi_net).max()
    face0, face1 = face_rows(basis, 0), face_rows(basis, 1)
    assert np.abs(face0[PIN]).max() <= ZERO * top               # held in every mode
    for i, j in ((2, 2), (2, 3), (3, 3), (4, 2), (SHARED[0], SHARED[1])):
        assert np.abs(face0[i, j]).max() > MOVES * top           # the other free points move
    assert np.abs(face1[2, 2]).max() > MOVES * top
    # the pinned point stays where the bake put it: its rest place is the baked shape's
    # (written to the STEP file and read back: 1e-9 of the net's size of 2 covers the digits)
    assert np.abs(basis.rest_net()[row] - shape[row]).max() <= 1e-9 * 2.0
    assert abs(basis.rest_net()[row, 2]) > 1e-6          # and the baked shape did move it
    # the page is told: in the free set no more, and still (flags: compared exactly)
    free = decode(data["free_mask"], "u1").astype(bool)
    still = decode(data["still_mask"], "u1").astype(bool)
    assert not free[row] and free[:row].all() and free[row + 1:].all() and still[row]
    # kept under the baked file's face numbers (0 and 1 here as before)
    assert session.scenario.raw["boundary"]["faces_free_points"] == {"0": every_point_but(PIN)}


def test_a_point_two_faces_share_is_held_on_both(served):
    client, session = served
    classes = decode(session.payload()["body"]["classes"], "<i4")
    a, b = SHARED[0] * N + SHARED[1], N * N + 0 * N + SHARED[1]     # face 0 (5, 3), face 1 (0, 3)
    assert classes[a] == classes[b]                      # one point of the body (integers)
    assert np.sum(classes == classes[a]) == 2
    assert classes[PIN[0] * N + PIN[1]] not in np.delete(classes, PIN[0] * N + PIN[1])
    # face 0 fixes it alone (face 1 not listed): the library holds face 1's copy too
    reply = pin(client, session, {"0": every_point_but(SHARED)})
    assert reply.status_code == 200, reply.text
    basis = session.basis
    top = np.abs(basis.phi_net).max()
    assert np.abs(face_rows(basis, 0)[SHARED]).max() <= ZERO * top
    assert np.abs(face_rows(basis, 1)[0, SHARED[1]]).max() <= ZERO * top
    assert np.abs(face_rows(basis, 1)[0, 2]).max() > MOVES * top    # its neighbour moves
    still = decode(reply.json()["still_mask"], "u1").astype(bool)
    assert still[a] and still[b]


def test_a_pin_keeps_the_painted_set_under_the_baked_files_face_numbers(tmp_path):
    """Faces 1, 2 of ``three.step`` are faces 0, 1 of the baked file: a pin on face 2
    (patch 1) is then kept as face 1's."""
    three_strips(tmp_path)
    text = BODY.replace('path = "two.step"', 'path = "three.step"\nfaces = [1, 2]')
    client, session = serve_sheet(tmp_path, text, resolution=R)
    reply = pin(client, session, {"2": every_point_but(PIN)})
    assert reply.status_code == 200, reply.text
    assert reply.json()["body"]["faces"] == [0, 1]
    assert session.scenario.raw["boundary"]["faces_free_points"] == {"1": every_point_but(PIN)}
    top = np.abs(session.basis.phi_net).max()
    assert np.abs(face_rows(session.basis, 1)[PIN]).max() <= ZERO * top
    assert np.abs(face_rows(session.basis, 0)[PIN]).max() > MOVES * top


def test_save_writes_the_pin_and_run_holds_the_point(served, tmp_path):
    client, session = served
    reply = pin(client, session, {"0": every_point_but(PIN)})
    assert reply.status_code == 200, reply.text
    push = PushMessage(index=2 * R + 2, force=(0.0, 0.0, -1.0), t_on=0.0, t_off=0.5)
    path, text = session.save(SaveMessage(version=reply.json()["version"], t_end=1.0,
                                          pushes=[push]))
    assert "faces_free_points = { 0 = [" in text
    scenario = load_scenario(path)
    assert scenario.raw["boundary"]["faces_free_points"] == {"0": every_point_but(PIN)}
    moved = run_saved(path, text, tmp_path, session)
    scale = max(np.abs(m).max() for m in moved)
    assert scale > 0
    # the file's nets are decimal text: the pinned point is at rest to the digits written
    # (1e-12), its moving neighbours far above (1e-2 of the largest motion)
    assert np.abs(moved[0][:, PIN[0], PIN[1]]).max() <= 1e-12 * max(scale, 1.0)
    assert np.abs(moved[0][:, 2, 2]).max() > 1e-2 * scale


@pytest.mark.parametrize("extra, words", [
    ({"faces_free_points": {"7": [[2, 2]]}}, "face 7 is not in this body"),
    ({"faces_free_points": {"0": [[6, 1]]}}, "[6, 1] is not a control point of face 0"),
    ({"faces_free_points": {"0": []}}, "face 0: is empty"),
    ({"free_points": [[2, 2]]}, "this is a body"),
])
def test_a_bad_pin_is_refused_and_nothing_is_baked(served, tmp_path, extra, words):
    client, session = served
    reply = client.post("/api/bake", json={"version": 1, "q": small_shape(session).tolist(),
                                           **extra})
    assert reply.status_code == 400, reply.text
    assert words in reply.json()["error"] and "two.toml" not in reply.json()["error"]
    assert session.version == 1 and not list(tmp_path.glob("*baked*"))   # the basis stays


def test_a_bodys_pin_is_refused_on_one_surface(tmp_path):
    client, session = serve_sheet(tmp_path, SHEET, resolution=5)
    q = np.zeros(3 * session.basis.lam.size)
    reply = client.post("/api/bake", json={"version": 1, "q": q.tolist(),
                                           "faces_free_points": {"0": [[1, 1]]}})
    assert reply.status_code == 400 and "this is one surface" in reply.json()["error"]
    assert session.version == 1 and not list(tmp_path.glob("*baked*"))


def test_resolve_and_pin_messages_share_their_bounds():
    from pydantic import ValidationError

    from splinedeform.sculpt.messages import BakeMessage, describe_error

    with pytest.raises(ValidationError) as info:
        BakeMessage.model_validate({"version": 1, "q": [0.0] * 3, "free_points": [[1, 1]],
                                    "faces_free_points": {"0": [[1, 1]]}})
    assert "not both" in describe_error(info.value)
