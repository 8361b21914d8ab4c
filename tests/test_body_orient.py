"""A pressure on a closed Brep body pushes along the Brep's outward normal on every face.

A Brep face marked reversed (OpenCASCADE's ``TopAbs_REVERSED``, rhino3dm's
``BrepFace.OrientationIsReversed``) has the outward normal ``-(S_u × S_v)``. The faces
are read with their orientation (``info["reversed"]`` of
:func:`splinedeform.cad_body.read_body`), the body carries one sign per face
(:attr:`splinedeform.body.Body.orientation`) and a pressure's vector on a face is turned
with it; the surfaces keep their parameters.

Checked independently of the files' flags on OpenCASCADE's filleted box (convex, so a
face's outward normal is the one with ``n · (x - c) > 0``, ``c`` the box's centre):
the faces read reversed are those whose ``S_u × S_v`` points inwards, an internal pressure
has no resultant (``∮ n dA = 0``), and the shell under it bulges outwards: the top and
bottom move out and the volume grows.
"""

from __future__ import annotations

import numpy as np
import pytest

import splinedeform as sd
from splinedeform.physics.plate_body import BodyReduction
from splinedeform.quadrature import gauss_points
from splinedeform.refine import refine_surface

pytest.importorskip("OCP", reason="the 'cad-step' extra (cadquery-ocp) is not installed")

from test_body_fillet import SIZE, centre, face_at, filleted_box  # noqa: E402,F401

CENTRE = 0.5 * np.asarray(SIZE)


def inward(surface: sd.Surface) -> bool:
    """Whether ``S_u × S_v`` at the middle of the domain points into the convex box."""
    u, v = (np.array([x]) for x in centre(surface))
    normal = np.cross(surface.derivative(u, v, 1, 0), surface.derivative(u, v, 0, 1))
    return float(np.dot(normal.ravel(), surface.evaluate(u, v).ravel() - CENTRE)) < 0


def signs_of(reversed_: list[bool]) -> list[int]:
    return [-1 if r else 1 for r in reversed_]


def resultant(body: sd.Body, signs: tuple[int, ...]) -> tuple[float, float]:
    """``(|Σ F_k|, Σ |F_k|)`` of a unit pressure's vector on every control point."""
    F = BodyReduction(None, body.patches, None, signs).field(sd.Pressure(1.0))
    return float(np.linalg.norm(F.sum(axis=0))), float(np.linalg.norm(F, axis=1).sum())


def test_the_faces_read_reversed_are_those_turned_inwards(filleted_box):
    from splinedeform.cad_body import read_body
    from splinedeform.cad_faces import faces_text, read_faces

    surfaces, _, info = read_body(filleted_box)
    turned = [k for k, r in enumerate(info["reversed"]) if r]
    assert turned and len(turned) < len(surfaces)          # some, not all
    assert turned == [k for k, s in enumerate(surfaces) if inward(s)]
    listing = read_faces(filleted_box)
    assert [f["face"] for f in listing["faces"] if f["reversed"]] == turned
    assert (f"reversed in their Brep (outward normal -(S_u × S_v)): face(s) "
            f"{', '.join(map(str, turned))}") in faces_text(listing)


def test_a_pressure_on_the_filleted_box_has_no_resultant(filleted_box):
    from splinedeform.cad_body import read_body

    surfaces, topology, info = read_body(filleted_box)
    body = sd.Body(surfaces, topology.interfaces, orientation=signs_of(info["reversed"]))
    plate = sd.BodyModel(body, sd.Material(w10=1.0, w01=1.0))
    F = plate.reduction.field(sd.Pressure(1.0))
    total = float(np.linalg.norm(F, axis=1).sum())
    # ∮ n dA = 0: the faces' quadrature errors cancel between mirrored faces, so the sum
    # is round-off; held to 1e-9 of the total |force| (the bound)
    assert np.linalg.norm(F.sum(axis=0)) <= 1e-9 * total
    assert resultant(body, body.orientation)[0] <= 1e-9 * total
    # each face's own x_u × x_v, as before the fix: a resultant of several per cent
    wrong, _ = resultant(body, ())
    assert wrong > 1e-2 * total


def test_a_shell_body_under_internal_pressure_grows(filleted_box):
    from splinedeform.cad_body import read_body
    from splinedeform.physics.shell import ShellMaterial
    from splinedeform.physics.shell_model import ShellModel
    from splinedeform.pipeline_body import body_static

    surfaces, _, info = read_body(filleted_box)
    patches = [refine_surface(s, (1, 1), (1, 1)) for s in surfaces]
    body = sd.Body(patches, orientation=signs_of(info["reversed"]))
    model = ShellModel(body, ShellMaterial(1.0e4, 0.3, 0.05))
    F = model.reduction.field(sd.Pressure(1.0)).reshape(-1, 3)
    # as above: round-off, held to 1e-9 of the total |force|
    assert np.linalg.norm(F.sum(axis=0)) <= 1e-9 * np.linalg.norm(F, axis=1).sum()
    nets = body_static(model, sd.Pressure(1.0)).net_displacement()
    # the top and the bottom (2 × 3, the most compliant faces) bulge outwards (the stiffer
    # walls, 1 high, are drawn in by their rotating edges: measured 0.07 and 0.03 inwards,
    # the top and bottom 0.26 outwards)
    for value, outward in ((0.0, -1.0), (SIZE[2], 1.0)):
        k = face_at(patches, 2, value)
        u, v = (np.array([x]) for x in centre(patches[k]))
        assert outward * patches[k].derivative(u, v, control_points=nets[k]).ravel()[2] > 0
    # the volume's first variation δV = Σ_faces ∫ d · n_out dA, n_out dA from the geometry
    # (S_u × S_v, turned where it points inwards), by Gauss quadrature: it grows
    grown = sum(volume_change(s, net) for s, net in zip(patches, nets))
    assert grown > 0


def volume_change(surface: sd.Surface, net: np.ndarray) -> float:
    """``∫∫ d · n_out |S_u × S_v| du dv`` of the displacement field of ``net``."""
    (xu, wu), (xv, wv) = (gauss_points(b, b.degree + 4) for b in (surface.basis_u,
                                                                  surface.basis_v))
    U, V = np.meshgrid(xu, xv, indexing="ij")
    area = np.cross(surface.derivative(U, V, 1, 0), surface.derivative(U, V, 0, 1))
    d = surface.derivative(U, V, control_points=net)
    sign = -1.0 if inward(surface) else 1.0
    return sign * float(np.einsum("a,b,abk,abk->", wu, wv, d, area))


def test_a_3dm_brep_face_marked_reversed_is_turned(tmp_path):
    r3 = pytest.importorskip("rhino3dm")
    from splinedeform.cad_body import read_body
    from splinedeform.cad_faces import read_faces

    path = tmp_path / "turned.3dm"
    model = r3.File3dm()
    brep = r3.Brep.CreateFromBox(r3.Box(r3.BoundingBox(0, 0, 0, 2, 3, 1)))
    assert not any(face.OrientationIsReversed for face in brep.Faces)
    brep.Faces[2].OrientationIsReversed = True       # its surface is left as it is
    model.Objects.AddBrep(brep)
    assert model.Write(str(path), 7)
    surfaces, topology, info = read_body(path)
    assert info["reversed"] == [k == 2 for k in range(6)]
    assert [f["reversed"] for f in read_faces(path)["faces"]] == info["reversed"]
    body = sd.Body(surfaces, topology.interfaces, orientation=signs_of(info["reversed"]))
    F = np.split(BodyReduction(None, body.patches, None, body.orientation).field(
        sd.Pressure(1.0)), 6)
    G = np.split(BodyReduction(None, body.patches).field(sd.Pressure(1.0)), 6)
    # face 2's vector is its surface's turned over, the others' are their surfaces' (the
    # same quadrature: equal to round-off)
    for k, (f, g) in enumerate(zip(F, G)):
        assert np.abs(f - (-g if k == 2 else g)).max() <= 1e-12 * np.abs(g).max()
    # the whole Brep flipped (rhino3dm's Brep.Flip): every face marked reversed
    brep.Flip()
    flipped = r3.File3dm()
    flipped.Objects.AddBrep(brep)
    assert flipped.Write(str(tmp_path / "flipped.3dm"), 7)
    assert read_body(tmp_path / "flipped.3dm")[2]["reversed"] == [k != 2 for k in range(6)]
