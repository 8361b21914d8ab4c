"""A body's free set painted face by face on the sculpting page (sculpt/body_paint.py),
through the server API as the page drives it: the two flat faces of :mod:`sculpt_body_files`
(face 0 ``[0, 1] × [0, 1]``, face 1 ``[1, 2] × [0, 1]``, cubic 6 × 6 nets, sharing face 0's
``u1`` = face 1's ``u0``), every boundary edge clamped.

With every edge clamped, face 0's points that can move are rows 2 .. 5 (rows 0, 1 held by
``u0``; row 5 the shared edge, which no preset holds) of columns 2, 3 (columns 0, 1 and
4, 5 held by ``v0`` and ``v1``). A fixed control point is no unknown: its row of the
constraint map ``T`` is empty, so its row of every mode ``T Φ`` is an empty sum, exactly 0;
the tests allow 1e-14 of the largest entry all the same (the brief's bound, far below any
mode that moves a point: those entries are above 1e-3 of the largest here).
"""

from __future__ import annotations

import json

import numpy as np
import pytest

pytest.importorskip("OCP", reason="the body's STEP shell needs OpenCASCADE (the extra 'step')")
from body_patches import flat_patch  # noqa: E402
from sculpt_body_files import BODY, two_faces  # noqa: E402
from sculpt_client import serve_sheet  # noqa: E402 (skips without the extra)

import splinedeform as sd  # noqa: E402
from splinedeform.body import BodyModel  # noqa: E402
from splinedeform.scenario import build, load_scenario  # noqa: E402
from splinedeform.sculpt.export import decode  # noqa: E402
from splinedeform.sculpt.messages import PushMessage, SaveMessage  # noqa: E402

pytestmark = pytest.mark.filterwarnings("ignore:Using `httpx`")
R = 6
N = 6                                   # each face's net: 3 cubic spans, 6 × 6 points
MATERIAL = {"mass": 1.0, "damping": 2.0, "rayleigh": 0.0, "w10": 1.0, "w01": 1.0,
            "w20": 0.0, "w11": 0.0, "w02": 0.0}
EVERY = {"u0": "clamped", "u1": "clamped", "v0": "clamped", "v1": "clamped"}
#: face 0 paints two of its interior points free; face 1 is not listed (it all moves)
PAINTED = [[2, 2], [3, 3]]
ZERO = 1e-14          # fixed points: empty rows of T, exactly 0 (module docstring)
MOVES = 1e-3          # a point a mode moves: above this fraction of the largest entry


@pytest.fixture()
def served(tmp_path):
    two_faces(tmp_path)
    return serve_sheet(tmp_path, BODY, resolution=R)


def resolve(client, faces_free_points):
    return client.post("/api/resolve", json={"material": MATERIAL, "boundary": EVERY,
                                             "faces_free_points": faces_free_points})


def face_rows(basis, patch):
    """The modes on patch ``patch``'s net, ``(n_u, n_v, k)``."""
    offsets = basis.net_offsets()
    return basis.phi_net[offsets[patch]:offsets[patch + 1]].reshape(N, N, -1)


def test_a_painted_face_moves_at_its_listed_points_only(served):
    client, session = served
    reply = resolve(client, {"0": PAINTED})
    assert reply.status_code == 200, reply.text
    data = reply.json()
    basis = session.basis
    top = np.abs(basis.phi_net).max()
    face0, face1 = face_rows(basis, 0), face_rows(basis, 1)
    listed = np.zeros((N, N), bool)
    listed[tuple(np.array(PAINTED).T)] = True
    assert np.abs(face0[~listed]).max() <= ZERO * top        # every other point of face 0
    for i, j in PAINTED:
        assert np.abs(face0[i, j]).max() > MOVES * top
    # face 1 is not listed: its interior moves; its u0 row is face 0's u1 row (one point
    # of the body, fixed on face 0), so it is held too
    assert np.abs(face1[2, 2]).max() > MOVES * top
    assert np.abs(face1[0]).max() <= ZERO * top
    # the modes are those of the body's model built directly with fixed = [mask, None]
    # (the constructor's own masks, not the page's path): two dense eigensolves of the
    # same matrices, equal to 1e-9 of the largest eigenvalue
    direct = BodyModel(basis.patches, sd.Material(w10=1.0, w01=1.0, damping=2.0),
                       boundary="clamped", fixed=[~listed, None])
    lam = np.sort(direct.eigen()[0])
    got = np.sort(decode(data["lam"], "<f8"))
    assert got.size == lam.size == direct.n_free
    assert np.abs(got - lam).max() <= 1e-9 * lam.max()
    # the page is told which points are in the free set and which cannot move (flags:
    # compared exactly)
    free = decode(data["free_mask"], "u1").astype(bool)
    still = decode(data["still_mask"], "u1").astype(bool)
    # flags as 0/1: equal when they differ by less than half a unit
    assert np.abs(free[:N * N].reshape(N, N).astype(int) - listed.astype(int)).max() < 0.5
    assert free[N * N:].all()
    assert not still[:N * N].reshape(N, N)[listed].any()
    assert still[:N * N].reshape(N, N)[~listed].all() and still[N * N:].reshape(N, N)[0].all()
    # nothing painted: every face moves again
    reply = resolve(client, None)
    assert reply.status_code == 200, reply.text
    assert decode(reply.json()["free_mask"], "u1").all()
    assert np.abs(face_rows(session.basis, 0)[2, 3]).max() > MOVES * np.abs(session.basis.phi_net).max()


def run_saved(path, text, folder, session) -> list[np.ndarray]:
    """``splinedeform run`` of a saved scenario (its outputs cut to the net file, 5
    frames): per face of the session's body the frames' displacement from rest."""
    from typer.testing import CliRunner

    from splinedeform import cli

    path.write_text(text.replace('formats = ["report", "images", "viewer"]',
                                 'formats = ["json"]'))
    out = folder / "out"
    result = CliRunner().invoke(cli.app, ["run", str(path), "-o", str(out), "--frames", "5"])
    assert result.exit_code == 0, result.output
    nets = json.loads(next(out.glob("*_nets.json")).read_text())["nets"]
    rest = [s.control_points for s in session.basis.patches]
    return [np.asarray(nets[str(f)]["control_points"]) - rest[f][None]
            for f in range(len(rest))]


def test_save_writes_the_painted_set_and_run_holds_the_same_points(served, tmp_path):
    client, session = served
    reply = resolve(client, {"0": PAINTED})
    assert reply.status_code == 200, reply.text
    push = PushMessage(index=2 * R + 2, force=(0.0, 0.0, -1.0), t_on=0.0, t_off=0.5)
    path, text = session.save(SaveMessage(version=reply.json()["version"], t_end=1.0,
                                          pushes=[push]))
    assert "faces_free_points = { 0 = [[2, 2], [3, 3]] }" in text
    scenario = load_scenario(path)
    assert scenario.raw["boundary"]["faces_free_points"] == {"0": PAINTED}
    built = build(scenario)
    assert built.model.n_free == session.basis.model.n_free
    moved = run_saved(path, text, tmp_path, session)
    listed = np.zeros((N, N), bool)
    listed[tuple(np.array(PAINTED).T)] = True
    scale = max(np.abs(m).max() for m in moved)
    assert scale > 0
    # the file's nets are decimal text: fixed points are at rest to the digits written
    # (the rest net itself is read back to 1e-12), far below the moving points' 1e-2
    assert np.abs(moved[0][:, ~listed]).max() <= 1e-12 * max(scale, 1.0)
    assert np.abs(moved[0][:, listed]).max() > 1e-2 * scale
    assert np.abs(moved[1][:, 0]).max() <= 1e-12 * max(scale, 1.0)   # the shared edge


@pytest.mark.parametrize("points, words", [
    ({"7": [[2, 2]]}, "face 7 is not in this body"),
    ({"1": [[2, 2], [6, 1]]}, "face 1[2]: [6, 1] is not a control point of face 1"),
    ({"0": []}, "face 0: is empty"),
])
def test_a_bad_face_or_index_is_refused_naming_the_face(served, points, words):
    client, session = served
    reply = resolve(client, points)
    assert reply.status_code == 400, reply.text
    error = reply.json()["error"]
    assert error.startswith("Free set: the painted control points of face") and words in error
    assert "two.toml" not in error and session.version == 1        # the basis stays


def test_each_kind_of_free_set_is_refused_where_it_does_not_apply(served, tmp_path):
    client, session = served
    reply = client.post("/api/resolve", json={"material": MATERIAL, "boundary": EVERY,
                                              "free_points": PAINTED})
    assert reply.status_code == 400 and "this is a body" in reply.json()["error"]
    reply = client.post("/api/resolve", json={"material": MATERIAL, "boundary": EVERY,
                                              "faces_free_points": {"x": PAINTED}})
    assert reply.status_code == 422 and "faces_free_points.x" in reply.json()["error"]
    reply = client.post("/api/resolve", json={"material": MATERIAL, "boundary": EVERY,
                                              "faces_free_points": {"0": [[2.5, 1]]}})
    assert reply.status_code == 422 and "faces_free_points.0.0.0" in reply.json()["error"]
    from sculpt_client import SHEET

    sheet, _ = serve_sheet(tmp_path / "..", SHEET, resolution=5)
    reply = sheet.post("/api/resolve", json={"material": MATERIAL, "boundary": {"u0": "clamped"},
                                             "faces_free_points": {"0": [[1, 1]]}})
    assert reply.status_code == 400 and "this is one surface" in reply.json()["error"]


def three_strips(folder):
    """Three unit squares in a row as one shell of ``folder/three.step``; the body opened
    with ``faces = [1, 2]`` has face numbers 1, 2 (its patches 0, 1)."""
    from splinedeform.export.body import write_body_step

    faces = [flat_patch((x, x + 1.0), (0.0, 1.0), (3, 3)) for x in (0.0, 1.0, 2.0)]
    write_body_step(folder / "three.step", faces, [f.control_points for f in faces], "mm",
                    shell=True)


def test_bake_keeps_the_painted_set_under_the_new_files_face_numbers(tmp_path):
    """A bake writes the body's faces as a new file whose faces are numbered 0, 1, …: the
    painted set of face 2 (patch 1) is then that of face 1, the same control points."""
    three_strips(tmp_path)
    text = BODY.replace('path = "two.step"', 'path = "three.step"\nfaces = [1, 2]')
    client, session = serve_sheet(tmp_path, text, resolution=R)
    assert session.basis.model.body.faces == (1, 2)
    reply = resolve(client, {"2": PAINTED})
    assert reply.status_code == 200, reply.text
    before = decode(reply.json()["free_mask"], "u1").copy()
    assert not before[N * N:].all() and before[:N * N].all()
    q = np.zeros(3 * session.basis.lam.size)
    q[2] = 1e-2                                  # a small shape to bake
    reply = client.post("/api/bake", json={"version": 2, "q": q.tolist()})
    assert reply.status_code == 200, reply.text
    assert reply.json()["body"]["faces"] == [0, 1]
    assert session.scenario.raw["boundary"]["faces_free_points"] == {"1": PAINTED}
    after = decode(reply.json()["free_mask"], "u1").astype(int)      # flags as 0/1
    assert after.shape == before.shape and np.abs(after - before.astype(int)).max() < 0.5
    top = np.abs(session.basis.phi_net).max()
    kept = face_rows(session.basis, 1)
    listed = np.zeros((N, N), bool)
    listed[tuple(np.array(PAINTED).T)] = True
    assert np.abs(kept[~listed]).max() <= ZERO * top


def test_the_message_bounds_a_bodys_painted_points_together():
    from pydantic import ValidationError

    from splinedeform.sculpt.messages import MAX_NET_POINTS, ResolveMessage, describe_error

    half = [[0, 0]] * (MAX_NET_POINTS // 2 + 1)      # each face within the limit, not both
    for extra, words in (({"faces_free_points": {"0": half, "1": half}},
                          f"more than the {MAX_NET_POINTS}"),
                         ({"faces_free_points": {"0": PAINTED}, "free_points": PAINTED},
                          "not both")):
        with pytest.raises(ValidationError) as info:
            ResolveMessage.model_validate({"material": MATERIAL, "boundary": EVERY, **extra})
        assert words in describe_error(info.value)
    message = ResolveMessage.model_validate({"material": MATERIAL, "boundary": EVERY,
                                             "faces_free_points": {"3": PAINTED}})
    assert message.faces_free_points == {"3": [(2, 2), (3, 3)]}
