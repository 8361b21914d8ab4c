"""One-dimensional B-spline bases against closed forms and independent implementations."""

from math import comb

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.interpolate import BSpline

from splinedeform.basis import KNOT_KINDS, BSplineBasis, cardinal_bspline
from splinedeform.errors import InputError

SETTINGS = settings(max_examples=40, deadline=None)


@st.composite
def bases(draw, kinds=KNOT_KINDS, degrees=(1, 5)):
    """A basis of any kind, degree, cell count and length."""
    kind = draw(st.sampled_from(kinds))
    degree = draw(st.integers(*degrees))
    low = degree + 1 if kind == "periodic" else 1
    cells = draw(st.integers(low, low + 10))
    length = draw(st.floats(0.1, 10.0))
    return BSplineBasis(degree, cells, length, kind)


def unit_points(draw, count=12):
    return np.array(draw(st.lists(st.floats(0.0, 1.0), min_size=1, max_size=count)))


def cubic_pieces(x):
    """Closed form of ``b^3`` on its four unit intervals (DESIGN.md §1.1)."""
    return np.select(
        [(x >= 0) & (x < 1), (x >= 1) & (x < 2), (x >= 2) & (x < 3), (x >= 3) & (x <= 4)],
        [x**3 / 6, (-3 * x**3 + 12 * x**2 - 12 * x + 4) / 6,
         (3 * x**3 - 24 * x**2 + 60 * x - 44) / 6, (4 - x) ** 3 / 6], 0.0)


def cubic_piece_derivatives(x):
    d1 = np.select(
        [(x >= 0) & (x < 1), (x >= 1) & (x < 2), (x >= 2) & (x < 3), (x >= 3) & (x <= 4)],
        [x**2 / 2, (-9 * x**2 + 24 * x - 12) / 6, (9 * x**2 - 48 * x + 60) / 6,
         -((4 - x) ** 2) / 2], 0.0)
    d2 = np.select(
        [(x >= 0) & (x < 1), (x >= 1) & (x < 2), (x >= 2) & (x < 3), (x >= 3) & (x <= 4)],
        [x, (-18 * x + 24) / 6, (18 * x - 48) / 6, 4 - x], 0.0)
    d3 = np.select([(x > 0) & (x < 1), (x > 1) & (x < 2), (x > 2) & (x < 3), (x > 3) & (x < 4)],
                   [1.0, -3.0, 3.0, -1.0], 0.0)
    return d1, d2, d3


# -- the cardinal B-spline -------------------------------------------------------------
def test_cardinal_cubic_equals_the_closed_form_pieces():
    x = np.linspace(-1.0, 5.0, 601)
    np.testing.assert_allclose(cardinal_bspline(x, 3), cubic_pieces(x), atol=1e-15)
    # known values: b^3(1) = 1/6, b^3(2) = 2/3
    np.testing.assert_allclose(cardinal_bspline([1.0, 2.0, 3.0], 3), [1 / 6, 2 / 3, 1 / 6])


def test_cardinal_cubic_derivatives_equal_the_closed_form():
    b = BSplineBasis(3, 8, 8.0, "uniform")   # h = 1: function j is b^3(x - (j - 3))
    x = np.linspace(0.0, 8.0, 801)
    x = x[np.abs(x - np.round(x)) > 1e-9]   # the third derivative jumps at the knots
    j = 5
    expected = cubic_piece_derivatives(x - (j - 3))
    for order in (1, 2, 3):
        np.testing.assert_allclose(b(x, order)[:, j], expected[order - 1], atol=1e-13)
    np.testing.assert_allclose(b(x, 4)[:, j], 0.0)


@pytest.mark.parametrize("degree", [1, 2, 3, 4, 5, 6])
def test_cardinal_symmetry_support_and_positivity(degree):
    x = np.linspace(-2.0, degree + 3.0, 1001)
    b = cardinal_bspline(x, degree)
    np.testing.assert_allclose(b, cardinal_bspline(degree + 1 - x, degree), atol=1e-14)
    outside = (x <= 0) | (x >= degree + 1)
    assert np.all(b[outside] == 0.0)
    assert np.all(b[~outside] > 0.0)
    # integral 1: trapezoidal rule on a fine grid (b is C^{n-1}, the rule is O(dx^2))
    xs = np.linspace(0.0, degree + 1.0, 20001)
    assert np.trapezoid(cardinal_bspline(xs, degree), xs) == pytest.approx(1.0, abs=1e-7)


@pytest.mark.parametrize("degree", [2, 3, 4, 5])
def test_cardinal_recurrence_is_the_integral_of_the_lower_degree(degree):
    """b^n(x) = ∫_{x-1}^x b^{n-1}, checked with 20-point Gauss on each unit piece."""
    gx, gw = np.polynomial.legendre.leggauss(20)
    x = np.array([0.3, 1.0, 1.7, 2.5, degree + 0.2])
    total = np.zeros_like(x)
    for left in (np.floor(x) - 1, np.floor(x)):   # [x-1, x] over two unit cells
        a, b = np.maximum(left, x - 1), np.minimum(left + 1, x)
        nodes = 0.5 * (a + b)[:, None] + 0.5 * (b - a)[:, None] * gx
        total += 0.5 * (b - a) * (cardinal_bspline(nodes, degree - 1) @ gw)
    np.testing.assert_allclose(cardinal_bspline(x, degree), total, atol=1e-14)


# -- bases on an interval -----------------------------------------------------------------
@SETTINGS
@given(data=st.data(), basis=bases())
def test_partition_of_unity_and_vanishing_derivatives(data, basis):
    x = unit_points(data.draw) * basis.length
    for order in range(basis.degree + 2):
        total = basis(x, order).sum(axis=1)
        scale = basis.h ** (-order)   # derivative entries are of size h^{-j}
        np.testing.assert_allclose(total, 1.0 if order == 0 else 0.0,
                                   atol=1e-12 * max(1.0, scale))


@SETTINGS
@given(data=st.data(), basis=bases())
def test_basis_values_are_non_negative_with_n_plus_one_non_zero(data, basis):
    x = unit_points(data.draw) * basis.length
    B = basis(x)
    # Mathematically B >= 0; the recurrences evaluate each value with O(degree) roundings
    # of O(1) terms, so round-off may leave a few ulps below zero (-1.2e-15 was seen at the
    # right end of an open knot vector): allow 64 ulps of 1.
    assert np.all(B >= -64 * np.finfo(float).eps)
    assert np.all((np.abs(B) > 1e-300).sum(axis=1) <= basis.degree + 1)


@SETTINGS
@given(data=st.data(), basis=bases())
def test_derivatives_against_central_differences(data, basis):
    x = unit_points(data.draw) * basis.length
    eps = 1e-5 * basis.h
    # stay inside one cell so the difference quotient sees one polynomial piece
    s = np.mod(x / basis.h, 1.0)
    x = x + np.where((s < 1e-3) | (s > 1 - 1e-3), 0.5 * basis.h, 0.0)
    x = np.where(x > basis.length - 2 * eps, basis.length - 0.5 * basis.h, x)
    for order in range(1, basis.degree + 1):
        fd = (basis(x + eps, order - 1) - basis(x - eps, order - 1)) / (2 * eps)
        exact = basis(x, order)
        tol = 1e-5 * basis.h ** (-order) * 10 ** order
        np.testing.assert_allclose(exact, fd, atol=tol)


@pytest.mark.parametrize("kind", ["uniform", "open"])
@pytest.mark.parametrize("degree", [1, 2, 3, 4, 5])
def test_all_derivative_orders_equal_scipy_bsplines(kind, degree):
    """Every order ``0..n`` of the per-span Bernstein form against scipy's ``BSpline``.

    scipy evaluates by its own de Boor recurrence: an independent implementation.
    """
    cells, length = 7, 2.1
    basis = BSplineBasis(degree, cells, length, kind)
    x = np.random.default_rng(degree).uniform(0.0, length, 200)
    index, values = basis.nonzero_derivatives(x, degree)
    cell = basis.span(x)
    # indices (integers): equal when they differ by less than half a unit
    assert np.abs(index - (cell[:, None] + np.arange(degree + 1))).max() < 0.5
    splines = BSpline(basis.knots, np.eye(basis.size), degree, extrapolate=False)
    for order in range(degree + 1):
        dense = np.take_along_axis(splines(x, nu=order), index, axis=1)
        # 1e-13 of the order's largest value: both are sums of O(n²) roundings of terms no
        # larger than it (the goal the evaluation is held to)
        np.testing.assert_allclose(values[order], dense, rtol=0,
                                   atol=1e-13 * np.abs(dense).max())


@pytest.mark.parametrize("degree", [2, 3, 4, 5])
@pytest.mark.parametrize("h", [0.25, 1.0, 3.0])
def test_higher_derivative_formula_against_the_cardinal_bspline(degree, h):
    """D^j b^n_{k,h} = h^{-j} Σ_i (-1)^i C(j,i) b^{n-j}_{k+i,h}   (DESIGN.md §1.1)."""
    cells = 6
    basis = BSplineBasis(degree, cells, cells * h, "uniform")
    x = np.random.default_rng(7).uniform(0.0, cells * h, 100)
    for j in range(basis.size):
        k = j - degree                      # Höllig's index
        for order in range(1, degree + 1):
            if order < degree:
                lower = [cardinal_bspline(x / h - (k + i), degree - order)
                         for i in range(order + 1)]
            else:                           # b^0 = 1 on [0, 1)
                lower = [((x / h - (k + i) >= 0) & (x / h - (k + i) < 1)).astype(float)
                         for i in range(order + 1)]
            expected = h ** (-order) * sum((-1) ** i * comb(order, i) * lower[i]
                                           for i in range(order + 1))
            np.testing.assert_allclose(basis(x, order)[:, j], expected,
                                       atol=1e-11 * h ** (-order))


@pytest.mark.parametrize("kind", ["open", "uniform"])
@pytest.mark.parametrize("degree", [1, 2, 3, 4, 5])
def test_non_periodic_bases_equal_scipy_bsplines(kind, degree):
    """scipy.interpolate.BSpline on the full knot vector is an independent implementation."""
    basis = BSplineBasis(degree, 5, 1.7, kind)
    x = np.concatenate([np.linspace(0.0, 1.7, 97), [0.0, 1.7]])
    reference = BSpline(basis.knots, np.eye(basis.size), degree)
    assert basis.knots.size == basis.size + degree + 1
    for order in range(degree + 1):
        expected = reference(x, nu=order) if order else reference(x)
        np.testing.assert_allclose(basis(x, order), expected,
                                   atol=1e-12 * max(1.0, basis.h ** (-order)))


@pytest.mark.parametrize("degree", [1, 2, 3, 4])
def test_periodic_basis_is_the_uniform_basis_wrapped(degree):
    """Periodic function j sums the uniform functions j + n + q m (q integer) on [0, L]."""
    cells, length = degree + 3, 2.5
    periodic = BSplineBasis(degree, cells, length, "periodic")
    uniform = BSplineBasis(degree, cells, length, "uniform")
    x = np.linspace(0.0, length, 61, endpoint=False)   # D^n jumps at x = L ≡ 0
    fold = np.zeros((uniform.size, periodic.size))
    fold[np.arange(uniform.size), np.mod(np.arange(uniform.size) - degree, cells)] = 1.0
    for order in range(degree + 1):
        np.testing.assert_allclose(periodic(x, order), uniform(x, order) @ fold,
                                   atol=1e-12 * periodic.h ** (-order))


@SETTINGS
@given(data=st.data(), basis=bases(kinds=("periodic",)))
def test_periodic_basis_is_periodic_with_its_derivatives(data, basis):
    x = unit_points(data.draw) * basis.length
    shifts = data.draw(st.integers(-3, 3))
    for order in range(basis.degree):
        np.testing.assert_allclose(basis(x + shifts * basis.length, order), basis(x, order),
                                   atol=1e-9 * basis.h ** (-order))
    # continuity across the seam x = L ≡ 0 of the derivatives 0..n-1
    eps = 1e-9 * basis.length
    for order in range(basis.degree):
        left, right = basis([basis.length - eps], order), basis([0.0], order)
        np.testing.assert_allclose(left, right, atol=1e-6 * basis.h ** (-order - 1))


@pytest.mark.parametrize("degree", [1, 2, 3, 5])
def test_open_basis_interpolates_its_end_coefficients(degree):
    basis = BSplineBasis(degree, 4, 3.0, "open")
    B = basis([0.0, 3.0])
    expected = np.zeros((2, basis.size))
    expected[0, 0] = expected[1, -1] = 1.0
    np.testing.assert_allclose(B, expected, atol=1e-15)
    knots = basis.knots
    assert np.all(knots[: degree + 1] == 0.0) and np.all(knots[-degree - 1:] == 3.0)


@pytest.mark.parametrize("kind", KNOT_KINDS)
def test_layout_sizes_and_knots(kind):
    basis = BSplineBasis(3, 6, 3.0, kind)
    assert basis.h == pytest.approx(0.5)
    assert basis.size == (6 if kind == "periodic" else 9)
    assert basis.periodic == (kind == "periodic")
    if kind != "open":
        np.testing.assert_allclose(basis.knots, np.arange(-3, 10) * 0.5)


@pytest.mark.parametrize("kind", KNOT_KINDS)
@pytest.mark.parametrize("degree", [1, 2, 3, 4])
def test_greville_abscissae_are_ordered_in_the_domain_and_unisolvent(kind, degree):
    basis = BSplineBasis(degree, 9, 2.0, kind)
    g = basis.greville()
    assert g.shape == (basis.size,)
    assert np.all((g >= 0.0) & (g <= 2.0))
    if kind != "periodic":
        assert np.all(np.diff(g) > 0) and g[0] == 0.0 and g[-1] == pytest.approx(2.0)
    assert np.linalg.cond(basis(g)) < 1e3
    if kind == "open":   # knot averages (t_{j+1} + ... + t_{j+n}) / n
        t = basis.knots
        averages = np.array([t[j + 1: j + degree + 1].mean() for j in range(basis.size)])
        np.testing.assert_allclose(g, averages)


@pytest.mark.parametrize("degree", [3, 4, 5])
def test_uniform_collocation_stays_well_conditioned_as_cells_grow(degree):
    conditions = [np.linalg.cond(b(b.greville()))
                  for b in (BSplineBasis(degree, m, 1.0, "uniform") for m in (8, 32, 128))]
    assert max(conditions) < 2 * min(conditions)


def test_matrix_is_sparse_with_the_dense_values():
    basis = BSplineBasis(3, 5, 1.0, "open")
    x = np.linspace(0.0, 1.0, 11)
    A = basis.matrix(x, 1)
    assert A.shape == (11, 8) and A.nnz <= 11 * 4
    dense = basis(x, 1)
    # two evaluations of the same derivative (sparse matrix and dense call): a few roundings
    # of values of size up to cells · degree / length = 15
    assert np.abs(A.toarray() - dense).max() <= 1e-12 * max(np.abs(dense).max(), 1.0)


# -- bad input ---------------------------------------------------------------------------
@pytest.mark.parametrize("args, words", [
    ((0, 4), "degree must be an integer >= 1"),
    ((1.5, 4), "degree must be an integer >= 1"),
    ((True, 4), "degree must be an integer >= 1"),
    ((3, 0, 1.0, "open"), "at least 1 cell"),
    ((3, 2.5, 1.0, "open"), "cells must be an integer"),
    ((3, 3, 1.0, "periodic"), r"cells >= degree \+ 1"),
    ((2, 4, 0.0, "open"), "length must be finite and > 0"),
    ((2, 4, np.nan, "open"), "length must be finite and > 0"),
    ((2, 4, 1.0, "closed"), "knot kind must be one of"),
])
def test_bad_construction_says_what_is_allowed(args, words):
    with pytest.raises(InputError, match=words):
        BSplineBasis(*args)


def test_bad_parameters_say_what_is_allowed():
    basis = BSplineBasis(3, 4, 2.0, "open")
    with pytest.raises(InputError, match="finite"):
        basis([0.5, np.nan])
    with pytest.raises(InputError, match=r"outside the domain \[0, 2\]"):
        basis([2.5])
    with pytest.raises(InputError, match=r"outside the domain"):
        basis.nonzero(-0.1)
    with pytest.raises(InputError, match="derivative order must be an integer >= 0"):
        basis.nonzero_derivatives([0.5], -1)
    with pytest.raises(InputError, match="degree must be an integer >= 1"):
        cardinal_bspline([0.5], 0)
    # periodic bases accept any real parameter
    periodic = BSplineBasis(3, 4, 2.0, "periodic")
    np.testing.assert_allclose(periodic([2.5]), periodic([0.5]), atol=1e-15)
    assert issubclass(InputError, ValueError)
