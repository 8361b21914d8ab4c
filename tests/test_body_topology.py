"""Interfaces found geometrically: shared edges, seams, poles, boundary and non-manifold
edges, orientation and conformity, with a tolerance relative to the body's size."""

from __future__ import annotations

import numpy as np
import pytest

import splinedeform as sd
from splinedeform.body import Interface, find_topology
from splinedeform.body.topology import TOLERANCE

from body_patches import flat_patch


def box(size: float = 1.0) -> list[sd.Surface]:
    """The six faces of the cube ``[0, size]³``, each a flat patch placed by a coordinate
    permutation (some reversed in u, so their interfaces run both ways)."""
    square = flat_patch((0, size), (0, size), (2, 2))
    P = square.control_points                                    # (x, y, 0)
    faces = []
    for axes, level in (((0, 1, 2), 0.0), ((0, 1, 2), size), ((0, 2, 1), 0.0),
                        ((0, 2, 1), size), ((1, 2, 0), 0.0), ((1, 2, 0), size)):
        net = np.zeros_like(P)
        net[..., axes[0]], net[..., axes[1]] = P[..., 0], P[..., 1]
        net[..., axes[2]] = level
        if level:
            net = net[::-1]
        faces.append(sd.Surface(net, square.basis_u, square.basis_v))
    return faces


def test_box_of_six_patches() -> None:
    topology = find_topology(box())
    assert topology.summary() == {"shared": 12, "seam": 0, "boundary": 0, "non_manifold": 0,
                                  "poles": 0, "non_conforming": 0}
    assert {i.reversed for i in topology.interfaces} == {False, True}
    # every edge of every face is in exactly one interface
    ends = [(i.a, i.edge_a) for i in topology.interfaces] + \
        [(i.b, i.edge_b) for i in topology.interfaces]
    assert sorted(ends) == sorted((p, e) for p in range(6) for e in ("u0", "u1", "v0", "v1"))
    # the tolerance follows the body's size: 1e-6 of the diagonal √3·size
    big = find_topology(box(1000.0))
    assert big.tol == pytest.approx(TOLERANCE * 1000.0 * np.sqrt(3), rel=1e-12)
    assert big.summary() == topology.summary()


def test_box_membrane_stays_closed_under_pressure() -> None:
    model = sd.BodyModel(box(), sd.Material(w10=1.0, w01=1.0, damping=1.0))
    assert model.rigid_modes == 1
    nets = model.dynamic(sd.Pressure(1.0), 5.0).control_points(5.0)
    # corners: the three faces' corner control points are one point (merged, round-off)
    corners = np.concatenate([net[[0, 0, -1, -1], [0, -1, 0, -1]] for net in nets])
    distances = np.linalg.norm(corners[:, None] - corners[None], axis=-1)
    assert np.all(np.sort(distances, axis=1)[:, 2] < 1e-12)


def test_gap_beyond_the_tolerance_is_a_boundary() -> None:
    left = flat_patch((0, 0.5), (0, 1), (2, 2))
    right = flat_patch((0.5, 1), (0, 1), (2, 2))
    near = sd.Surface(right.control_points + [1e-7, 0, 0], right.basis_u, right.basis_v)
    far = sd.Surface(right.control_points + [1e-5, 0, 0], right.basis_u, right.basis_v)
    # diagonal √2 (plus the shift): tolerance 1.4e-6, between the two shifts
    assert find_topology([left, near]).summary()["shared"] == 1
    assert find_topology([left, far]).summary() == {
        "shared": 0, "seam": 0, "boundary": 8, "non_manifold": 0, "poles": 0,
        "non_conforming": 0}
    assert find_topology([left, far], tol=1e-4).summary()["shared"] == 1


def test_same_curve_another_parametrisation_matches_but_does_not_conform() -> None:
    left = flat_patch((0, 0.5), (0, 1), (2, 2))
    right = flat_patch((0.5, 1), (0, 1), (2, 2))
    net = right.control_points.copy()
    net[..., 1] = net[..., 1] ** 2          # y = v² along every row: the same segments
    bent = sd.Surface(net, right.basis_u, right.basis_v)
    topology = find_topology([left, bent])
    assert topology.interfaces == (Interface(0, "u1", 1, "u0", False, False),)
    assert topology.aligned == (False,)
    body = sd.Body([left, bent])
    assert body.conforming().summary()["non_conforming"] == 1     # no knot makes it conform
    with pytest.raises(sd.InputError, match="patch 0 edge u1 and patch 1 edge u0: the edges "
                                            "meet, but their parametrisations"):
        sd.BodyModel(body, sd.Material(w10=1.0, w01=1.0))


def test_poles_and_seams_of_a_hemisphere() -> None:
    dome = sd.shapes.half_sphere(cells=(8, 4), knots=("open", "open"))
    assert find_topology([dome]).summary() == {"shared": 0, "seam": 1, "boundary": 1,
                                               "non_manifold": 0, "poles": 1,
                                               "non_conforming": 0}
    periodic = sd.shapes.half_sphere(cells=(8, 4))        # periodic in u: no seam edges
    topology = find_topology([periodic])
    assert topology.poles == ((0, "v1"),) and topology.boundary == ((0, "v0"),)
    assert topology.interfaces == ()


def test_bad_patches_are_refused() -> None:
    with pytest.raises(sd.InputError, match="non-empty list of splinedeform.Surface"):
        find_topology([])
    with pytest.raises(sd.InputError, match="tolerance must be finite and > 0"):
        find_topology(box(), tol=-1.0)
    with pytest.raises(sd.InputError, match="edge u1 of patch 3"):
        sd.Body(box()[:2], interfaces=[Interface(0, "u0", 3, "u1")])


def quarter_tube(spans_v: int, angle0: float) -> sd.Surface:
    """A quarter of the unit cylinder from ``angle0``: an exact NURBS arc in u (degree 2,
    weights 1, √2/2, 1) times a line of ``spans_v`` quadratic spans in v."""
    from splinedeform.knots import KnotVectorBasis, RationalBasis
    arc = RationalBasis(KnotVectorBasis(2, [0, 0, 0, 1, 1, 1]), [1, np.sqrt(0.5), 1])
    bv = KnotVectorBasis(2, np.concatenate([[0, 0], np.linspace(0, 1, spans_v + 1), [1, 1]]))
    c, s = np.cos(angle0), np.sin(angle0)
    corners = np.array([[c, s], [c - s, s + c], [-s, c]])        # the arc's control polygon
    z = bv.greville()
    net = np.concatenate([np.repeat(corners[:, None], z.size, 1),
                          np.broadcast_to(z, (3, z.size))[..., None]], axis=-1)
    return sd.Surface(net, arc, bv)


def test_rational_patches_made_conforming_by_exact_knot_insertion() -> None:
    a, b = quarter_tube(1, 0.0), quarter_tube(3, np.pi / 2)
    body = sd.Body.from_surfaces([a, b])
    assert body.summary()["shared"] == 1 and body.summary()["non_conforming"] == 1
    refined = body.conforming()
    assert refined.summary()["non_conforming"] == 0
    assert refined[0].shape == b.shape
    U, V = np.meshgrid(np.linspace(0, 1, 9), np.linspace(0, 1, 9), indexing="ij")
    # Boehm's insertion in homogeneous coordinates: the geometry does not move (round-off)
    np.testing.assert_allclose(refined.evaluate(0, U, V), a.evaluate(U, V), atol=1e-14)
    radius = np.linalg.norm(refined.evaluate(0, U, V)[..., :2], axis=-1)
    np.testing.assert_allclose(radius, 1.0, atol=1e-14)     # still the exact circle
    lower, upper = refined.bounding_box()
    np.testing.assert_allclose(lower, [-1, 0, 0], atol=1e-14)
    np.testing.assert_allclose(upper, [1, 1, 1], atol=1e-14)
    # a quadratic and a cubic edge: no knot makes them conform
    cubic = flat_patch((0, 1), (0, 1), (1, 1))
    quadratic = sd.Surface(np.stack(np.meshgrid([1.0, 1.5, 2.0], [0.0, 0.5, 1.0],
                                                indexing="ij") + (np.zeros((3, 3)),), -1),
                           *(sd.KnotVectorBasis(2, [0, 0, 0, 1, 1, 1]),) * 2)
    mixed = sd.Body([cubic, quadratic])
    assert mixed.conforming().summary()["non_conforming"] == 1
