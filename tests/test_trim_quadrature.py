"""Quadrature on trimmed regions against exact areas and moments."""

import numpy as np
import pytest

from splinedeform.errors import InputError
from splinedeform.trim import CUT, INSIDE, OUTSIDE, CircleLoop, Grid, PolygonLoop, TrimDomain
from splinedeform.trim import classify_cells, trim_quadrature


@pytest.mark.parametrize("cells", [5, 8, 13])
def test_disc_area_and_second_moments(cells):
    # exact circle trim: ∫ 1 = π r², ∫ x² = π r⁴/4, ∫ x²y² = π r⁶/24 about the centre;
    # Gauss-Green with 8 points on each arc converges spectrally, 1e-10 is the task's bar
    r, c = 0.37, 0.52
    q = trim_quadrature(TrimDomain(CircleLoop((c, 0.49), r)), Grid((cells, cells)), 8)
    x, y = q.points[:, 0] - c, q.points[:, 1] - 0.49
    assert abs(q.integrate(np.ones_like(x)) - np.pi * r ** 2) < 1e-10
    assert abs(q.integrate(x ** 2) - np.pi * r ** 4 / 4) < 1e-10
    assert abs(q.integrate(y ** 2) - np.pi * r ** 4 / 4) < 1e-10
    assert abs(q.integrate(x * y)) < 1e-10
    assert abs(q.integrate(x ** 2 * y ** 2) - np.pi * r ** 6 / 24) < 1e-10


def test_square_with_a_hole():
    # square of side s minus a disc of radius r: area s² - π r², ∫ x² = s⁴/12 - π r⁴/4
    s, r = 0.8, 0.2
    square = PolygonLoop([[0.1, 0.1], [0.9, 0.1], [0.9, 0.9], [0.1, 0.9]])
    q = trim_quadrature(TrimDomain(square, (CircleLoop((0.5, 0.5), r),)), Grid((7, 7)), 8)
    x, y = q.points[:, 0] - 0.5, q.points[:, 1] - 0.5
    assert abs(q.integrate(np.ones_like(x)) - (s * s - np.pi * r * r)) < 1e-10
    assert abs(q.integrate(x ** 2) - (s ** 4 / 12 - np.pi * r ** 4 / 4)) < 1e-10
    assert abs(q.integrate(x ** 2 * y ** 2) - (s ** 6 / 144 - np.pi * r ** 6 / 24)) < 1e-10


def test_polygon_rule_is_exact_for_polynomials():
    # a slanted triangle cut by the grid: ∫ over the triangle of x⁴ y³ by the exact
    # vertex formula of a degree-7 monomial is replaced by a 40-point tensor rule on the
    # Duffy map (independent, exact to round-off); 1e-13 allows round-off of ~1e3 terms
    tri = np.array([[0.13, 0.21], [0.87, 0.34], [0.41, 0.93]])
    q = trim_quadrature(TrimDomain(PolygonLoop(tri)), Grid((6, 5)), 5)
    f = lambda p: p[..., 0] ** 4 * p[..., 1] ** 3
    g, w = np.polynomial.legendre.leggauss(40)
    a, b = np.meshgrid(0.5 * (g + 1), 0.5 * (g + 1), indexing="ij")
    ww = np.outer(w, w) / 4 * (1 - a)                      # Duffy: (a, b) -> (a, (1-a) b)
    p = tri[0] + a[..., None] * (tri[1] - tri[0]) + ((1 - a) * b)[..., None] * (tri[2] - tri[0])
    e1, e2 = tri[1] - tri[0], tri[2] - tri[0]
    jac = abs(e1[0] * e2[1] - e1[1] * e2[0])
    exact = float(np.sum(ww * f(p)) * jac)
    assert abs(q.integrate(f(q.points)) - exact) < 1e-13


def test_cell_classes():
    classes = classify_cells(TrimDomain(CircleLoop((0.5, 0.5), 0.3)), Grid((10, 10)))
    assert classes[5, 5] == INSIDE and classes[0, 0] == OUTSIDE and classes[2, 5] == CUT
    assert classes[9, 9] == OUTSIDE


def test_loop_outside_the_parameter_domain_is_refused():
    with pytest.raises(InputError, match="leaves the parameter domain"):
        trim_quadrature(TrimDomain(CircleLoop((0.9, 0.5), 0.3)), Grid((4, 4)), 4)
