"""Bézier pieces fitted to curves, and loops made of them (trim/bezier.py,
trim/piecewise_loop.py), against closed forms: polynomials reproduced, the circle's
area and second moments, orientation."""

import numpy as np
import pytest

from splinedeform.errors import InputError
from splinedeform.trim import Grid, PiecewiseLoop, PolygonLoop, TrimDomain, trim_quadrature
from splinedeform.trim.bezier import evaluate, fit_pieces, join_loop

C, R = np.array([0.5, 0.45]), 0.3


def circle(t):
    return C + R * np.stack([np.cos(t), np.sin(t)], axis=-1)


def disc_loop(tol):
    pieces = fit_pieces(circle, np.linspace(0, 2 * np.pi, 5), 2, tol)
    return PiecewiseLoop.from_pieces(join_loop([pieces], 1e-9, "circle"))


def test_a_polynomial_curve_is_reproduced():
    def cubic(t):
        return np.stack([1 + t - 2 * t ** 3, 0.5 * t ** 2 + 3 * t ** 3], axis=-1)

    breaks = np.array([0.0, 0.3, 1.0])
    pieces = fit_pieces(cubic, breaks, 3, 1e-14)
    assert pieces.shape == (2, 4, 2)                   # one cubic piece per interval
    tau = np.linspace(0, 1, 17)
    got = evaluate(pieces, tau)
    want = np.stack([cubic(a + (b - a) * tau) for a, b in zip(breaks[:-1], breaks[1:])])
    # interpolation at 4 points of a cubic: exact up to the round-off of a 4×4 solve
    # (values of size 4): 1e-14
    assert np.abs(got - want).max() < 1e-14


def test_a_circle_is_followed_within_the_tolerance():
    tol = 1e-12
    pieces = fit_pieces(circle, np.linspace(0, 2 * np.pi, 5), 2, tol)
    assert pieces.shape[1] == 10                       # rational: degree-9 pieces
    tau = np.linspace(0, 1, 201)
    radius = np.hypot(*(evaluate(pieces, tau) - C).transpose(2, 0, 1))
    # the error is checked at 27 points per piece; between them it is the same smooth
    # error curve: within 2 tol on 201 points
    assert np.abs(radius - R).max() < 2 * tol


@pytest.mark.parametrize("tol", [1e-10, 1e-12])
def test_disc_and_square_with_a_hole_area_and_second_moments(tol):
    hole = disc_loop(tol)
    # the loop is within tol of the circle: its area within tol × perimeter (2e-12 / 2e-10)
    assert hole.signed_area == pytest.approx(np.pi * R ** 2, abs=tol * 2 * np.pi * R * 1.1)
    square = PolygonLoop([[0, 0], [1, 0], [1, 1], [0, 1]])
    # a grid whose lines miss the square's far sides (they would lie on its last line)
    grid = Grid((9, 9), (1.1, 1.1))
    for domain, sign, base in ((TrimDomain(hole), 1, 0.0), (TrimDomain(square, (hole,)), -1, 1)):
        rule = trim_quadrature(domain, grid, 6)
        x, y = rule.points.T
        disc_xx = np.pi * R ** 2 * C[0] ** 2 + np.pi * R ** 4 / 4
        disc_xy = np.pi * R ** 2 * C[0] * C[1]
        square_xx, square_xy = 1 / 3, 1 / 4
        # Gauss–Green, exact for these polynomials on the degree-9 pieces (6 points across,
        # 6 along: degree 11 each way); the pieces' own error (tol) bounds the difference
        want = [base + sign * np.pi * R ** 2, base * square_xx + sign * disc_xx,
                base * square_xy + sign * disc_xy]
        got = [rule.integrate(np.ones_like(x)), rule.integrate(x * x), rule.integrate(x * y)]
        assert np.allclose(got, want, rtol=0, atol=max(10 * tol, 1e-12))
        assert abs(got[0] - domain.area()) < 1e-12    # two exact rules on the same pieces


def test_orientation_is_normalised_by_the_domain():
    loop = disc_loop(1e-10)
    backwards = loop.oriented(False)
    # the same pieces in reverse: the signed area changes sign (Gauss on the same spans)
    assert backwards.signed_area == pytest.approx(-loop.signed_area, rel=1e-14)
    # reversing reorders the same control points (no arithmetic): to one rounding of the
    # unit-size parameters
    np.testing.assert_allclose(backwards.pieces[0, 0], loop.pieces[-1, -1], rtol=0, atol=1e-15)
    domain = TrimDomain(PolygonLoop([[0, 0], [1, 0], [1, 1], [0, 1]]), (loop,))
    assert domain.holes[0].signed_area < 0 and domain.outer.signed_area > 0
    assert domain.contains([[0.5, 0.45], [0.05, 0.05]]).tolist() == [False, True]


def test_collinear_edges_apart_do_not_meet():
    # three edges on the line v = 0, the first and third apart: a simple polygon
    loop = PolygonLoop([[0, 0], [1, 0], [2, 0], [3, 0], [3, 1], [0, 1]])
    assert loop.signed_area == pytest.approx(3.0, abs=1e-15)   # shoelace of integers
    # a vertex (1, 0) on an edge of the same line, and a crossing, still meet
    for touching in ([[0, 0], [2, 0], [2, 1], [1, 1], [1, 0], [0.5, 1]],
                     [[0, 0], [1, 1], [1, 0], [0, 1]]):
        with pytest.raises(InputError, match="intersects itself"):
            PolygonLoop(touching)


def test_bad_pieces_are_refused():
    pieces = fit_pieces(circle, np.linspace(0, 2 * np.pi, 5), 2, 1e-10)
    with pytest.raises(InputError, match="the loop is open: piece 0 ends"):
        join_loop([pieces[:1], pieces[2:]], 1e-9, "two arcs")
    with pytest.raises(InputError, match="must be closed"):
        PiecewiseLoop.from_pieces(pieces[:3])
    with pytest.raises(InputError, match="not smooth there"):
        fit_pieces(lambda t: np.stack([t, np.where(t < 0.5, 0.0, 1.0)], -1),
                   np.array([0.0, 1.0]), 1, 1e-10, "a step")
