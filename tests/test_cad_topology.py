"""Placing a file's edges on the sides of its faces (cad_topology.py), on patches built here."""

import numpy as np

from splinedeform.cad import NurbsPatch, refine
from splinedeform.cad_topology import EDGE_KINDS, body_topology, side_curves

KNOTS = np.array([0, 0, 0, 1, 1, 1.0])


def sheet(corner, du, dv, splits=1) -> NurbsPatch:
    """The flat biquadratic sheet ``corner + s du + t dv`` on ``[0, 1]²`` (its sides
    straight, its parametrisation linear), knot spans split ``splits`` times."""
    s = np.linspace(0, 1, 3)
    P = (np.asarray(corner, float) + s[:, None, None] * np.asarray(du, float)
         + s[None, :, None] * np.asarray(dv, float))
    patch = NurbsPatch((2, 2), KNOTS, KNOTS, P, np.ones((3, 3)))
    return refine(patch, splits) if splits > 1 else patch


def edge(faces, a, b):
    """An edge from ``a`` to ``b`` used by ``faces``, sampled as the readers sample it."""
    t = (np.arange(9) + 0.5) / 9
    return {"faces": faces, "points": np.asarray(a, float) + t[:, None] * np.subtract(b, a)}


def test_two_sheets_meet_reversed_and_conforming_or_not():
    left = sheet([0, 0, 0], [1, 0, 0], [0, 1, 0])            # its u1 side is x = 1
    right = sheet([1, 1, 0], [1, 0, 0], [0, -1, 0])          # u0 is x = 1, v running down
    edges = [edge([0, 1], [1, 0, 0], [1, 1, 0])]
    topology = body_topology([left, right], edges, [0, 1])
    (joint,) = topology.interfaces
    assert (joint.a, joint.edge_a, joint.b, joint.edge_b) == (0, "u1", 1, "u0")
    assert joint.reversed and joint.conforming
    assert topology.counts == dict.fromkeys(EDGE_KINDS, 0) | {"shared": 1}
    # the same geometry on other knots along the edge: not conforming
    finer = sheet([1, 1, 0], [1, 0, 0], [0, -1, 0], splits=2)
    (joint,) = body_topology([left, finer], edges, [0, 1]).interfaces
    assert joint.reversed and not joint.conforming


def test_three_faces_on_one_edge_are_non_manifold_and_an_edge_off_the_sides_is_counted():
    fin = sheet([1, 0, 0], [0, 0, 1], [0, 1, 0])              # u0 on x = 1, standing up
    patches = [sheet([0, 0, 0], [1, 0, 0], [0, 1, 0]),
               sheet([1, 1, 0], [1, 0, 0], [0, -1, 0]), fin]
    edges = [edge([0, 1, 2], [1, 0, 0], [1, 1, 0]),
             edge([0], [0.5, 0, 0], [0.5, 1, 0])]             # across sheet 0: no side
    topology = body_topology(patches, edges, [0, 1, 2])
    assert topology.counts == dict.fromkeys(EDGE_KINDS, 0) | {
        "non_manifold": 1, "boundary": 1, "off_sides": 1}
    assert [(i.a, i.b) for i in topology.interfaces] == [(0, 1), (0, 2)]
    # faces left out of the body: the edge is a boundary of what is left
    topology = body_topology(patches, edges, [2])
    assert topology.counts["boundary"] == 1 and topology.interfaces == []


def test_side_curves_are_the_patch_evaluated_on_its_sides():
    patch = sheet([0, 0, 0], [1, 0, 0], [0, 2, 0], splits=3)
    sides = side_curves(patch)
    s = np.linspace(0, 1, sides["u0"].shape[0])
    # a linear map evaluated by two paths (one collocation matrix per direction against
    # the patch's own evaluator): round-off, 1e-14 of the size 2
    np.testing.assert_allclose(sides["u1"], patch.evaluate(np.array([1.0]), s)[0], atol=2e-14)
    np.testing.assert_allclose(sides["v0"], patch.evaluate(s, np.array([0.0]))[:, 0], atol=2e-14)
    np.testing.assert_allclose(sides["v1"][:, 1], 2.0, atol=2e-14)
