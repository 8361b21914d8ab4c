"""Trim loops: orientation, point-in-domain, signed distance and refusals of bad loops."""

import numpy as np
import pytest

from splinedeform.errors import InputError
from splinedeform.trim import CircleLoop, PolygonLoop, TrimDomain

SQUARE = [[0.1, 0.1], [0.9, 0.1], [0.9, 0.9], [0.1, 0.9]]


def test_orientation_is_normalised():
    hole = PolygonLoop([[0.4, 0.4], [0.6, 0.4], [0.6, 0.6], [0.4, 0.6]])   # counter-clockwise
    d = TrimDomain(PolygonLoop(SQUARE[::-1]), (hole,))
    assert d.outer.signed_area > 0 and d.holes[0].signed_area < 0
    # exact areas of axis-parallel polygons: 0.64 - 0.04, to round-off (1e-15)
    assert abs(d.area() - 0.60) < 1e-14


def test_point_in_domain_and_signed_distance_against_closed_forms():
    d = TrimDomain(PolygonLoop(SQUARE), (CircleLoop((0.5, 0.5), 0.2),))
    rng = np.random.default_rng(1)
    p = rng.uniform(0, 1, (2000, 2))
    r = np.hypot(p[:, 0] - 0.5, p[:, 1] - 0.5)
    box = np.maximum(np.abs(p[:, 0] - 0.5), np.abs(p[:, 1] - 0.5))
    expected = (box < 0.4) & (r > 0.2)
    # inside/outside as 0/1, compared to half a unit away from the loops: a point within
    # 1e-12 of a loop (round-off of coordinates of size 1) may fall either way
    clear = (np.abs(box - 0.4) > 1e-12) & (np.abs(r - 0.2) > 1e-12)
    got = d.contains(p).astype(float)
    assert clear.sum() > 1990 and np.abs(got - expected)[clear].max() <= 0.5
    # inside the convex square the distance to it is 0.4 - box, to the circle r - 0.2
    # (closed forms); 1e-14 is round-off of coordinates of size 1
    sd = d.signed_distance(p)
    sel = expected
    assert np.allclose(sd[sel], np.minimum(0.4 - box[sel], r[sel] - 0.2), atol=1e-14)
    assert np.all(sd[~expected] <= 0)


def test_self_intersecting_polygon_is_refused():
    with pytest.raises(InputError, match="intersects itself"):
        PolygonLoop([[0, 0], [2, 0], [2, 2], [1, -1]])


def test_crossing_loops_are_refused():
    with pytest.raises(InputError, match="trim loops cross"):
        TrimDomain(PolygonLoop(SQUARE), (CircleLoop((0.85, 0.5), 0.1),))
    with pytest.raises(InputError, match="trim loops cross"):
        TrimDomain(CircleLoop((0.5, 0.5), 0.4), (CircleLoop((0.5, 0.7), 0.3),))


def test_hole_outside_or_in_a_hole_is_refused():
    with pytest.raises(InputError, match="outside the outer loop"):
        TrimDomain(CircleLoop((0.3, 0.3), 0.2), (CircleLoop((0.8, 0.8), 0.05),))
    with pytest.raises(InputError, match="inside hole 1"):
        TrimDomain(CircleLoop((0.5, 0.5), 0.4),
                   (CircleLoop((0.5, 0.5), 0.2), CircleLoop((0.5, 0.5), 0.05)))


def test_degenerate_loops_are_refused():
    with pytest.raises(InputError, match="at least 3 vertices"):
        PolygonLoop([[0, 0], [1, 1]])
    with pytest.raises(InputError, match="no area"):
        PolygonLoop([[0, 0], [0.5, 0.5], [1, 1]])
    with pytest.raises(InputError, match="radius"):
        CircleLoop((0.5, 0.5), -1.0)


def _midpoints(loop):
    """Each span's midpoint: a polygon's segments', a Bézier-piece loop's at ``τ = 1/2``."""
    from splinedeform.trim import PiecewiseLoop

    if isinstance(loop, PiecewiseLoop):
        n = loop.degree
        from math import comb

        weights = np.array([comb(n, a) for a in range(n + 1)]) / 2.0 ** n
        return np.einsum("a,sak->sk", weights, loop.pieces)
    a, b = loop.segments()
    return 0.5 * (a + b)


def test_trim_edges_stay_with_their_spans_when_a_loop_is_turned():
    # clockwise outer loops are run the other way by TrimDomain; each span keeps the trim
    # edge it was given, found again by its midpoint (exact: the same points reordered)
    from splinedeform.trim import PiecewiseLoop

    square = [[0.0, 0.0], [0.0, 1.0], [1.0, 1.0], [1.0, 0.0]]          # clockwise
    polygon = PolygonLoop(square)
    corners = np.array(square + square[:1])
    pieces = np.stack([corners[:-1], 0.5 * (corners[:-1] + corners[1:]), corners[1:]], axis=1)
    piecewise = PiecewiseLoop.from_pieces(pieces)
    for loop, labels in ((polygon, (0, 0, 1, 2)), (piecewise, (0, 1, 1, 2))):
        domain = TrimDomain(loop, edges=(labels,))
        assert domain.outer is not loop and domain.edge_count(0) == 3
        given, turned = _midpoints(loop), _midpoints(domain.outer)
        for s, point in enumerate(turned):
            source = int(np.argmin(np.hypot(*(given - point).T)))
            assert np.allclose(given[source], point, rtol=0, atol=1e-15)
            assert domain.edges[0][s] == labels[source]
