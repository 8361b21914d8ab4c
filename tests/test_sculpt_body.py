"""Sculpting a body (sculpt/session.py, modal.py, save.py, history.py, shape_files.py): two
flat faces side by side, written here as one sewn STEP shell (their shared edge one edge of
the file), opened with ``faces = "all"`` and driven through the server API as the page
drives it.

Face 0 is ``[0, 1] × [0, 1]``, face 1 ``[1, 2] × [0, 1]`` (cubic, 3 × 3 spans, control
points at the Greville abscissae, so ``x(u, v) = (x0 + u, v, 0)``); they share the edge
``x = 1``: face 0's ``u1`` is face 1's ``u0``, with the same ``v``.
"""

from __future__ import annotations

import io
import zipfile

import numpy as np
import pytest

pytest.importorskip("rhino3dm", reason="the body's .3dm needs the extra 'cad'")
pytest.importorskip("OCP", reason="the body's STEP shell needs OpenCASCADE (the extra 'step')")
from body_patches import flat_patch  # noqa: E402
from sculpt_body_files import BODY, two_faces  # noqa: E402
from sculpt_client import serve_sheet  # noqa: E402 (skips without the extra)

import splinedeform as sd  # noqa: E402
from splinedeform.body import OnPatch  # noqa: E402
from splinedeform.export.nets import read_control_net  # noqa: E402
from splinedeform.scenario import build, parse_scenario  # noqa: E402
from splinedeform.sculpt import Push  # noqa: E402
from splinedeform.sculpt.export import decode  # noqa: E402
from splinedeform.sculpt.history import baked_nets  # noqa: E402
from splinedeform.sculpt.state import modal_history  # noqa: E402

pytestmark = pytest.mark.filterwarnings("ignore:Using `httpx`")
R = 6                                   # samples per direction of each face


@pytest.fixture()
def served(tmp_path):
    two_faces(tmp_path)
    return serve_sheet(tmp_path, BODY, resolution=R)


def index_of(patch: int, i: int, j: int) -> int:
    """The page's sample index: patch after patch, row-major within a patch."""
    return patch * R * R + i * R + j


def rung_down(basis, index, force):
    """``(q, nets, scale)``: the modal state long after a held push of ``force`` on sample
    ``index`` (t = 1000: rung down under damping 2, e^-1000), its nets per face and their
    largest displacement."""
    patch, u, v = basis.sample_point(index)
    q = modal_history(basis, [Push(u, v, force, 0.0, patch=patch)], [1e3])[0]
    nets = baked_nets(basis, q)
    return q, nets, max(np.abs(n - s.control_points).max() for n, s in zip(nets, basis.patches))


def shared_edges(nets, n=21):
    """Face 0's edge u = 1 and face 1's edge u = 0 of the nets, sampled at ``n`` v's."""
    faces = [flat_patch((0.0, 1.0), (0.0, 1.0), (3, 3)), flat_patch((1.0, 2.0), (0.0, 1.0), (3, 3))]
    v = np.linspace(0.0, 1.0, n)
    return (faces[0].with_control_points(nets[0]).evaluate(np.ones(n), v),
            faces[1].with_control_points(nets[1]).evaluate(np.zeros(n), v))


def test_a_body_opens_with_every_face_on_the_page(served):
    client, session = served
    data = client.get("/api/basis").json()
    assert data["grid"] == [2 * R, R] and len(data["faces"]) == 2
    assert data["body"]["faces"] == [0, 1] and data["body"]["units"] == "mm"
    assert [f["net"] for f in data["faces"]] == [[6, 6], [6, 6]]
    rest = decode(data["rest"]).reshape(2, R, R, 3)
    # float32 transport of coordinates in [0, 2]: 2**-23 relative
    assert np.allclose(rest[0, ..., 0].min(), 0.0, atol=1e-6) and np.allclose(rest[0, ..., 0].max(), 1.0)
    assert np.allclose(rest[1, ..., 0].min(), 1.0) and np.allclose(rest[1, ..., 0].max(), 2.0)
    page = client.get("/").text
    assert '"faces":[{' in page                     # the page has the faces' layout


def test_a_push_near_the_interface_moves_both_faces_and_keeps_the_seam_closed(served):
    """The complete modal basis' static limit of a push on face 0 next to the shared edge
    equals the body's direct static solve (sparse LU, another computation) to 1e-9 of the
    displacement (rounding of the eigensolve); the faces' edges agree to 1e-9 of it."""
    client, session = served
    basis = session.basis
    patch, u, v = basis.sample_point(index_of(0, R - 2, 2))
    assert patch == 0 and 0.7 < u < 1.0
    force = (0.0, 0.0, -1.0)
    q = modal_history(basis, [Push(u, v, force, 0.0, patch=0)], [1e3])[0]   # rung down
    nets = baked_nets(basis, q)
    static = basis.model.static(OnPatch(sd.Point(u, v, force), patch=0)).control_points()
    scale = max(np.abs(n - s.control_points).max() for n, s in zip(nets, basis.patches))
    assert scale > 1e-3
    for net, expect in zip(nets, static):
        assert np.abs(net - expect).max() <= 1e-9 * scale
    assert np.abs(nets[1] - basis.patches[1].control_points).max() > 0.05 * scale  # both move
    left, right = shared_edges(nets)
    assert np.abs(left - right).max() <= 1e-9 * scale


def test_the_exported_body_keeps_every_face_and_the_closed_seam(served, tmp_path):
    import rhino3dm

    client, session = served
    basis = session.basis
    q, nets, scale = rung_down(basis, index_of(1, 1, 3), (0.0, 0.2, 1.0))
    reply = client.post("/api/export", json={"version": 1, "q": q.ravel().tolist(), "format": "3dm"})
    assert reply.status_code == 200, reply.text
    path = tmp_path / "got.3dm"
    path.write_bytes(reply.content)
    model = rhino3dm.File3dm.Read(str(path))
    assert len(model.Objects) == 1 and model.Settings.ModelUnitSystem == rhino3dm.UnitSystem.Millimeters
    (obj,) = model.Objects                    # one Brep, its two faces joined along the seam
    assert [obj.Attributes.GetUserString(f"splinedeform.face {k}") for k in range(2)] == \
        ["two faces face 0", "two faces face 1"]
    brep = obj.Geometry
    assert brep.IsValid and len(brep.Faces) == 2 and len(brep.Edges) == 7
    for face, net in zip(brep.Faces, nets):
        srf = face.UnderlyingSurface().ToNurbsSurface()
        got = np.array([[[srf.Points[i, j].X, srf.Points[i, j].Y, srf.Points[i, j].Z]
                         for j in range(srf.Points.CountV)] for i in range(srf.Points.CountU)])
        # doubles through openNURBS: 1e-12 of the body's size (2)
        assert np.abs(got - net).max() <= 1e-12 * 2
    left, right = shared_edges(nets)
    assert np.abs(left - right).max() <= 1e-9 * scale
    # OBJ: one mesh welded across the shared edge (the R samples of the edge counted once)
    reply = client.post("/api/export", json={"version": 1, "q": q.ravel().tolist(), "format": "obj"})
    vertices = [line for line in reply.text.splitlines() if line.startswith("v ")]
    assert len(vertices) == 2 * R * R - R
    # the net: one JSON per face in a zip, each read back as the face's net
    reply = client.post("/api/export", json={"version": 1, "q": q.ravel().tolist(), "format": "json"})
    assert reply.status_code == 200 and reply.headers["content-type"] == "application/zip"
    with zipfile.ZipFile(io.BytesIO(reply.content)) as bundle:
        assert sorted(bundle.namelist()) == ["two_faces-shape-face-0.json", "two_faces-shape-face-1.json"]
        for k, net in enumerate(nets):
            (tmp_path / f"face{k}.json").write_bytes(bundle.read(f"two_faces-shape-face-{k}.json"))
            surface = read_control_net(tmp_path / f"face{k}.json")
            # repr floats read back exactly; 1e-15 of the body's size leaves room for rounding
            assert np.abs(surface.control_points - net).max() <= 1e-15 * 2


def test_save_names_the_faces_and_replays_with_run(served):
    """Each grab is a point load on its face; the saved scenario's body, solved by the
    analytic dynamic solve of the library, gives the session's closed form (the page's
    Python twin) on every face to 1e-9 of the largest displacement."""
    client, session = served
    basis = session.basis
    pushes = [{"index": index_of(0, 4, 3), "force": [0.0, 0.0, -1.0], "t_on": 0.0, "t_off": 0.5},
              {"index": index_of(1, 2, 2), "force": [0.1, 0.0, 0.6], "t_on": 0.3, "t_off": None}]
    reply = client.post("/api/save", json={"version": 1, "t_end": 1.2, "pushes": pushes})
    assert reply.status_code == 200, reply.text
    text = session.save_path.read_text()
    assert "face = 0" in text and "face = 1" in text and "2 faces of 6x6, 6x6" in text
    saved = parse_scenario(text, source=str(session.save_path), directory=session.save_path.parent)
    built = build(saved)
    times = np.linspace(0.0, 1.2, 7)
    got = built.model.dynamic(built.load, 1.2, modes=built.model.n_free).control_points(times)
    ours = []
    for p in pushes:
        patch, u, v = basis.sample_point(p["index"])
        ours.append(Push(u, v, tuple(p["force"]), p["t_on"],
                         np.inf if p["t_off"] is None else p["t_off"], patch))
    q = modal_history(basis, ours, list(times))
    expect = [np.stack([n for n in baked_nets(basis, qt)]) for qt in q]      # (F) x (P, ...)
    scale = max(np.abs(e - np.stack([s.control_points for s in basis.patches])).max() for e in expect)
    assert scale > 1e-3
    for f in range(times.size):
        for p in range(2):
            assert np.abs(got[p][f] - expect[f][p]).max() <= 1e-9 * scale


# the STEP reader compares each face's area inside its loops with its whole surface's
# (cad_faces.is_trimmed) and takes the sewn faces of a curved body for trimmed ones; the
# faces are whole, as the nets compared below show
@pytest.mark.filterwarnings("ignore:.*is trimmed; its whole underlying surface is used")
def test_bake_makes_the_pushed_body_the_rest_shape(served, tmp_path):
    client, session = served
    q, nets, _ = rung_down(session.basis, index_of(0, 3, 3), (0.0, 0.0, 2.0))
    reply = client.post("/api/bake", json={"version": 1, "q": q.ravel().tolist()})
    assert reply.status_code == 200, reply.text
    assert reply.json()["version"] == 2 and len(reply.json()["faces"]) == 2
    new = session.basis
    assert new.is_body and len(new.patches) == 2
    for surface, net in zip(new.patches, nets):    # the .3dm written and read back: 1e-12
        assert np.abs(surface.control_points - net).max() <= 1e-12 * 2
    assert session.scenario.surface.path.suffix == ".step"
    # the seam is still one edge: a push on the new body keeps it closed
    q2 = modal_history(new, [Push(0.9, 0.5, (0.0, 0.0, -1.0), 0.0, patch=0)], [1e3])[0]
    moved = baked_nets(new, q2)
    scale = max(np.abs(m - n).max() for m, n in zip(moved, nets))
    edges = [new.patches[0].with_control_points(moved[0]).evaluate(np.ones(9), np.linspace(0, 1, 9)),
             new.patches[1].with_control_points(moved[1]).evaluate(np.zeros(9), np.linspace(0, 1, 9))]
    assert scale > 1e-3 and np.abs(edges[0] - edges[1]).max() <= 1e-9 * scale


def test_a_body_refuses_a_free_region_and_edge_by_edge_presets(served):
    client, session = served
    material = {"mass": 1.0, "damping": 2.0, "rayleigh": 0.0, "w10": 1.0, "w01": 1.0,
                "w20": 0.0, "w11": 0.0, "w02": 0.0}
    same = {e: "pinned" for e in ("u0", "u1", "v0", "v1")}
    reply = client.post("/api/resolve", json={"material": material, "boundary": same,
                                              "free_region": {"u": [0.2, 0.8]}})
    assert reply.status_code == 400 and "not to a body" in reply.json()["error"]
    reply = client.post("/api/resolve", json={"material": material,
                                              "boundary": {**same, "u0": "clamped"}})
    assert reply.status_code == 400 and "one preset for every boundary edge" in reply.json()["error"]
    reply = client.post("/api/resolve", json={"material": material, "boundary": same})
    assert reply.status_code == 200, reply.text
    assert reply.json()["boundary"] == same and session.version == 2


def test_a_file_of_several_faces_loaded_from_the_page_opens_as_a_body(tmp_path):
    """The built-in sheet's session (every edge clamped) loads the two faces' STEP file: the
    modes are the body's (the same as a session opened on it, to 1e-9 relative: two
    eigensolves of the same matrices)."""
    sheet = BODY.replace('shape = "cad"\npath = "two.step"', 'shape = "plane"\ncells = 3')
    client, session = serve_sheet(tmp_path, sheet, resolution=R)
    source = tmp_path / "source"
    source.mkdir()
    two_faces(source)
    reply = client.post("/api/load", content=(source / "two.step").read_bytes(),
                        headers={"X-Sculpt-File-Name": "two.step",
                                 "Content-Type": "application/octet-stream"})
    assert reply.status_code == 200, reply.text
    assert reply.json()["body"]["faces"] == [0, 1] and session.basis.is_body
    _, direct = serve_sheet(source, BODY, resolution=R)
    lam, expect = session.basis.lam, direct.basis.lam
    assert np.abs(lam - expect).max() <= 1e-9 * expect.max()


def test_the_static_correction_of_a_truncated_body_basis_makes_a_held_push_exact(tmp_path):
    """With 4 of the body's modes, the modal static part plus the correction column of the
    grabbed sample (POST /api/correction) is the body's direct static solve at every
    sample of both faces, to 1e-9 of the displacement (sparse LU against eigenvectors)."""
    from sculpt_client import ORIGIN, TOKEN
    from starlette.testclient import TestClient

    from splinedeform.sculpt.guard import TOKEN_HEADER, Guard
    from splinedeform.sculpt.server import create_app
    from splinedeform.sculpt.session import Session

    two_faces(tmp_path)
    session = Session(parse_scenario(BODY, source="two.toml", directory=tmp_path),
                      resolution=R, modes=4, save_path=tmp_path / "saved.toml")
    client = TestClient(create_app(session, Guard.for_address("127.0.0.1", 8765, TOKEN)),
                        base_url=ORIGIN, headers={"Origin": ORIGIN, TOKEN_HEADER: TOKEN})
    basis, index = session.basis, index_of(1, 1, 2)
    assert basis.lam.size == 4 < basis.model.n_free
    reply = client.post("/api/correction", json={"version": 1, "index": index})
    assert reply.status_code == 200, reply.text
    column = decode(reply.json()["column"])                       # float32 on the wire
    modal = basis.phi_samples @ (basis.phi_samples[index] / basis.lam)
    patch, u, v = basis.sample_point(index)
    static = basis.model.static(OnPatch(sd.Point(u, v, (0.0, 0.0, 1.0)), patch=patch))
    expect = basis.sample_matrix() @ np.concatenate([n.reshape(-1, 3) for n in static.control_points()])
    expect = expect[:, 2] - basis.rest_samples()[:, 2]
    scale = np.abs(expect).max()
    assert np.abs(modal + session.correction.column(index) - expect).max() <= 1e-9 * scale
    # the page's copy in float32: each entry rounded by at most 2**-24 of itself, so
    # 2**-23 of the column's largest bounds them all
    exact = session.correction.column(index)
    assert np.abs(column - exact).max() <= 2**-23 * np.abs(exact).max()


def test_a_body_sampled_finer_than_the_page_draws_is_refused_naming_the_resolution(tmp_path):
    from splinedeform.errors import InputError
    from splinedeform.sculpt.session import Session

    two_faces(tmp_path)
    scenario = parse_scenario(BODY, source="two.toml", directory=tmp_path)
    with pytest.raises(InputError, match=r"2 faces sampled 300x300 .* --resolution 282 or less"):
        Session(scenario, resolution=300, modes=None, save_path=tmp_path / "saved.toml")
