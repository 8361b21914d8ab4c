"""Closed B-spline trim curves: area, containment, distance and quadrature against
independent computations on the curve itself."""

import numpy as np
import pytest

from splinedeform.errors import InputError
from splinedeform.trim import Grid, PolygonLoop, SplineLoop, TrimDomain, trim_quadrature

ANGLE = np.linspace(0, 2 * np.pi, 9)[:-1]
BLOB = np.stack([0.5 + 0.3 * np.cos(ANGLE),
                 0.5 + 0.125 * np.sin(3 * ANGLE) + 0.2 * np.sin(ANGLE)], -1)


def _boundary_integral(loop, integrand, points=12):
    """``∮ integrand(x, y) dy`` over the loop by Gauss per span (polynomial: exact)."""
    xi, w = np.polynomial.legendre.leggauss(points)
    t = (np.arange(loop.spans)[:, None] + 0.5 * (xi + 1)).ravel()
    p, d = loop.evaluate(t)
    return float(np.sum(np.tile(w, loop.spans) * 0.5 * integrand(p[:, 0], p[:, 1]) * d[:, 1]))


@pytest.mark.parametrize("cells", [5, 8, 13])
def test_area_and_moment_match_the_curve_integrals(cells):
    # ∫ 1 = ∮ x dy and ∫ x² = ⅓ ∮ x³ dy, computed on the curve alone (Green); the cell
    # rule must agree to round-off (1e-13 over ~100 pieces)
    loop = SplineLoop(BLOB, 3)
    q = trim_quadrature(TrimDomain(loop), Grid((cells, cells)), 8)
    x = q.points[:, 0]
    assert abs(q.integrate(np.ones_like(x)) - _boundary_integral(loop, lambda x, y: x)) < 1e-13
    assert abs(q.integrate(x ** 2) - _boundary_integral(loop, lambda x, y: x ** 3) / 3) < 1e-13


def test_spline_hole_in_a_square():
    # area 0.81 minus the spline's own area (shoelace-free Green integral), round-off 1e-13
    loop = SplineLoop(BLOB, 3)
    square = PolygonLoop([[0.05, 0.05], [0.95, 0.05], [0.95, 0.95], [0.05, 0.95]])
    domain = TrimDomain(square, (loop,))
    assert domain.holes[0].signed_area < 0
    q = trim_quadrature(domain, Grid((7, 7)), 8)
    assert abs(q.integrate(np.ones(len(q.weights))) - (0.81 - loop.signed_area)) < 1e-13


def test_containment_and_distance_against_a_fine_polygon():
    # the curve sampled at 200 points per span is within ~2e-6 of it (chord sagitta
    # κ Δs²/8 with κ <= 15, Δs <= 1.5e-3): containment agrees away from a 1e-5 band,
    # distances to 1e-5
    loop = SplineLoop(BLOB, 3)
    fine = PolygonLoop(loop.sample(200))
    rng = np.random.default_rng(5)
    p = rng.uniform(0, 1, (400, 2))
    far = fine.distance(p) > 1e-5
    assert np.array_equal(loop.encloses(p)[far], fine.encloses(p)[far])
    assert np.allclose(loop.distance(p), fine.distance(p), rtol=0, atol=1e-5)


def test_self_intersecting_spline_loop_is_refused():
    figure_eight = np.stack([0.5 + 0.3 * np.sin(ANGLE), 0.5 + 0.2 * np.sin(2 * ANGLE)], -1)
    with pytest.raises(InputError, match="intersects itself"):
        SplineLoop(figure_eight, 3)


def test_spline_loop_crossing_a_polygon_is_refused():
    square = PolygonLoop([[0.3, 0.3], [0.95, 0.3], [0.95, 0.95], [0.3, 0.95]])
    with pytest.raises(InputError, match="trim loops cross"):
        TrimDomain(square, (SplineLoop(BLOB, 3),))
