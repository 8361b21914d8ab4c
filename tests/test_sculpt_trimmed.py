"""Sculpting a trimmed face: the page gets the clipped mesh the exports draw, pushes move
the trimmed (WEB-spline) model, and a grab outside the trims is refused, through the
session and the server API."""

from __future__ import annotations

import numpy as np
import pytest

import splinedeform as sd
from splinedeform.errors import InputError
from splinedeform.scenario import load_scenario
from splinedeform.sculpt import Push
from splinedeform.sculpt.export import decode
from splinedeform.sculpt.messages import PushMessage, SaveMessage
from splinedeform.sculpt.state import modal_history
from trim_scenario import HEAD, RIM

R = 17          # samples per direction: 0.5 is sample 8, the disc's centre
CENTRE = 8 * R + 8
#: a membrane disc of radius 0.4 cut from the unit square, clamped on its rim
DISC = HEAD + RIM + """[material]
w10 = 1.0
w01 = 1.0
damping = 1.0
[solve]
kind = "modes"
"""


@pytest.fixture()
def served(tmp_path):
    from sculpt_client import serve_sheet

    return serve_sheet(tmp_path, DISC, resolution=R)


def test_the_page_gets_the_exports_clipped_mesh(served):
    from splinedeform.export.frames import tessellate_frames

    client, session = served
    data = client.get("/api/basis").json()
    basis = session.basis
    surface = basis.model.surface
    tri = decode(data["trim"]["triangles"], "<i4").reshape(-1, 3)
    rest = decode(data["rest"]).reshape(-1, 3)
    assert rest.shape[0] == basis.sample_count == R * R + len(data["trim"]["crossings"]["u"])
    inside = decode(data["trim"]["inside"], "u1")
    assert inside[tri].all()                                # only samples inside are drawn
    # the same triangles as the exports' mesh (an independent evaluation of the surface):
    # corner positions sorted, float32 transport of positions of size 1: 1e-6
    vertices, faces = tessellate_frames(surface, surface.control_points, R)
    ours = np.sort(np.sort(rest[tri].reshape(len(tri), -1), axis=1), axis=0)
    theirs = np.sort(np.sort(vertices[faces].reshape(len(faces), -1), axis=1), axis=0)
    assert ours.shape == theirs.shape and np.abs(ours - theirs).max() <= 1e-6
    # every crossing on the rim |p - c| = 0.4 (bisection to 2^-60 of a grid edge: 1e-12)
    c = data["trim"]["crossings"]
    radius = np.hypot(np.array(c["u"]) - 0.5, np.array(c["v"]) - 0.5)
    assert radius.size > 0 and np.abs(radius - 0.4).max() <= 1e-12
    # the grid points inside are those within the circle (none within 1e-9 of it at R = 17)
    g = np.linspace(0, 1, R)
    uu, vv = np.meshgrid(g, g, indexing="ij")
    within = np.hypot(uu - 0.5, vv - 0.5).ravel() < 0.4
    # inside/outside flags as 0/1: integers, compared to half a unit
    flags = inside[:R * R].astype(bool).astype(float)
    assert np.abs(flags - within.astype(float)).max() <= 0.5


def test_a_push_at_the_centre_moves_the_trimmed_model(served):
    """The page's closed form on its samples is the trimmed model's dynamics (every mode
    kept): the clamped rim stays put and the centre moves as ``Model.dynamic`` says."""
    _, session = served
    basis = session.basis
    pushes = [Push(0.5, 0.5, (0.0, 0.0, -1.0), t_on=0.0, t_off=0.4)]
    q = modal_history(basis, pushes, [0.3, 0.9])
    model = basis.model
    sol = model.dynamic([sd.Point(0.5, 0.5, (0.0, 0.0, -1.0), sd.Step(0.0, 0.4))], 1.0)
    for k, t in enumerate([0.3, 0.9]):
        d = basis.phi_samples @ q[k]
        ref = sol.displacement(t, np.array([0.5]), np.array([0.5]))[0]
        # two evaluations of the same modal sum: 1e-10 of the displacement
        assert np.abs(d[CENTRE] - ref).max() <= 1e-10 * np.abs(ref).max()
        assert abs(d[CENTRE, 2]) > 1e-3
        # the rim is held (weakly, by Nitsche's terms): the crossings, on the rim, move by
        # the discretisation error only (3e-4 of the centre at 10 cells; 1e-3 allowed), where
        # a disc not held there would move its rim by a fair part of its centre
        assert np.abs(d[R * R:]).max() <= 1e-3 * abs(d[CENTRE, 2])


def test_a_grab_outside_the_trims_is_refused(served):
    client, session = served
    basis = session.basis
    with pytest.raises(InputError, match="outside the trims"):
        basis.participation(0.02, 0.02)
    # sample 0 is the corner (0, 0): cut away
    reply = client.post("/api/correction", json={"version": session.version, "index": 0})
    assert reply.status_code == 400 and "outside the trims" in reply.json()["error"]
    corner = PushMessage(index=0, force=(0.0, 0.0, -1.0), t_on=0.0, t_off=0.5)
    with pytest.raises(InputError, match=r"pushes\[1\].index = 0: the point u = 0, v = 0"):
        session.save(SaveMessage(version=session.version, t_end=1.0, pushes=[corner]))
    centre = PushMessage(index=CENTRE, force=(0.0, 0.0, -1.0), t_on=0.0, t_off=0.5)
    path, _ = session.save(SaveMessage(version=session.version, t_end=1.0, pushes=[centre]))
    saved = load_scenario(path)
    # the sample grid point (8/16, 8/16) written with %.17g: 1e-15
    assert saved.surface.trim is not None and np.allclose(saved.loads[0].at, 0.5, atol=1e-15)


def test_the_obj_download_is_the_clipped_mesh(served):
    """Export shape → OBJ of a trimmed disc: the page's triangles, at the shape now."""
    client, session = served
    basis = session.basis
    q = np.zeros((basis.lam.size, 3))
    q[0, 2] = 0.5                                           # the lowest mode, lifted
    reply = client.post("/api/export", json={"version": session.version,
                                             "q": q.ravel().tolist(), "format": "obj"})
    assert reply.status_code == 200, reply.text
    lines = reply.text.splitlines()
    vertices = np.array([[float(x) for x in line.split()[1:]] for line in lines
                         if line.startswith("v ")])
    faces = [line for line in lines if line.startswith("f ")]
    assert len(faces) == len(basis.trimmed.triangles)
    # the page's samples inside the trims at the same shape: rest + Φ_s q
    shown = basis.rest_samples() + basis.phi_samples @ q
    used = np.unique(basis.trimmed.triangles)
    ours = np.sort(shown[used], axis=0)
    # %.17g text of two evaluations of the same sums: 1e-12 of the size
    assert vertices.shape == ours.shape
    assert np.abs(np.sort(vertices, axis=0) - ours).max() <= 1e-12


def test_a_body_of_trimmed_faces_is_drawn_on_their_regions_and_meets_along_the_trim():
    """A disc and the square less the disc, two trimmed faces coupled along the circle
    (tests/test_body_trimmed.py): each face's samples are its grid clipped to its region,
    the crossings of the two faces are the same points of the circle, and a push at the
    centre moves both faces' crossings alike."""
    from splinedeform.sculpt import sculpt_basis
    from test_body_trimmed import split_square

    model = sd.BodyModel(split_square(8, 12, degree=3), sd.Material(w10=1, w01=1, damping=1.0),
                         boundary="clamped", physics="parametric")
    basis = sculpt_basis(model, R)
    trimmed = basis.trimmed
    grids = 2 * R * R
    assert basis.sample_count == grids + len(trimmed.uv)
    # each face's triangles use only its own samples (grid rows or crossings)
    face = np.where(np.arange(basis.sample_count) < grids,
                    np.arange(basis.sample_count) // (R * R),
                    np.concatenate([np.zeros(grids, int), trimmed.patch])).astype(int)
    assert np.all(np.ptp(face[trimmed.triangles], axis=1) == 0)
    assert set(face[trimmed.triangles[:, 0]]) == {0, 1}
    # the same grid on the same square: the two faces cross the circle at the same points
    # (each bisected to round-off, 1e-12)
    ours, theirs = (trimmed.uv[trimmed.patch == p] for p in (0, 1))
    order0, order1 = np.lexsort(ours.T), np.lexsort(theirs.T)
    assert ours.shape == theirs.shape
    assert np.abs(ours[order0] - theirs[order1]).max() <= 1e-12
    q = modal_history(basis, [Push(0.5, 0.5, (0.0, 0.0, -1.0), 0.0, patch=0)], [50.0])[0]
    d = basis.phi_samples @ q
    at = grids + np.arange(len(trimmed.uv))
    jump = d[at[trimmed.patch == 0][order0]] - d[at[trimmed.patch == 1][order1]]
    # the penalty coupling along the circle leaves 2e-4 of the largest displacement at
    # these cubic faces of 8 and 12 cells (the body's own test: 1e-6 at 20 quartic cells);
    # 2e-3 allowed, where uncoupled faces would differ by the whole displacement there
    assert np.abs(jump).max() <= 2e-3 * np.abs(d).max()
    # the circle moves (not held): 3.6e-2 of the membrane's peak under its point force
    assert np.abs(d[at]).max() > 0.02 * np.abs(d).max()


def test_a_bake_keeps_the_trim(served):
    """Bake: the shape now becomes the rest shape of the same trimmed disc (its trim table
    kept with the baked net), solved again: the same unknowns, samples and triangles."""
    from splinedeform.sculpt.messages import BakeMessage

    _, session = served
    before = session.basis
    q = np.zeros((before.lam.size, 3))
    q[0, 2] = 0.1                                           # lift the lowest mode
    session.bake(BakeMessage(version=session.version, q=q.ravel().tolist()))
    after = session.basis
    assert session.scenario.surface.shape == "file" and after.model.surface.trim is not None
    assert after.model.n_free == before.model.n_free
    # the triangles' vertex indices: integers, compared to half a unit
    assert after.trimmed.triangles.shape == before.trimmed.triangles.shape
    assert np.abs(after.trimmed.triangles - before.trimmed.triangles).max() <= 0.5
    # the baked rest shape is the shape of q: rest + Φ_s q, to round-off of the net (1e-12)
    shape = before.rest_samples() + before.phi_samples @ q
    assert np.abs(after.rest_samples() - shape).max() <= 1e-12
