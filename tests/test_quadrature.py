"""Exact Gram matrices against closed forms, brute-force quadrature and their null spaces."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.integrate import quad

from splinedeform.basis import KNOT_KINDS, BSplineBasis, cardinal_bspline
from splinedeform.errors import InputError
from splinedeform.quadrature import gauss_points, gram_matrix, integrals

SETTINGS = settings(max_examples=30, deadline=None)


@st.composite
def bases(draw, kinds=KNOT_KINDS, degrees=(1, 5)):
    kind = draw(st.sampled_from(kinds))
    degree = draw(st.integers(*degrees))
    low = degree + 1 if kind == "periodic" else 1
    cells = draw(st.integers(low, low + 8))
    length = draw(st.floats(0.2, 5.0))
    return BSplineBasis(degree, cells, length, kind)


def brute_force_gram(basis, order, points=20):
    """``Bᵀ W B`` with 20-point Gauss–Legendre per cell (exact far beyond degree 2n)."""
    ref_x, ref_w = np.polynomial.legendre.leggauss(points)
    left = np.arange(basis.cells)[:, None] * basis.h
    x = (left + 0.5 * basis.h * (ref_x + 1)).ravel()
    w = np.tile(0.5 * basis.h * ref_w, basis.cells)
    B = basis(x, order)
    return B.T @ (w[:, None] * B)


def knot_averages(basis):
    """Greville abscissae ``(t_{j+1} + ... + t_{j+n}) / n`` from the knot vector itself."""
    t, n = basis.knots, basis.degree
    return np.array([t[j + 1: j + n + 1].mean() for j in range(basis.size)])


@SETTINGS
@given(basis=bases(), order=st.integers(0, 2))
def test_gram_is_symmetric_psd_and_equals_brute_force(basis, order):
    order = min(order, basis.degree)
    G = gram_matrix(basis, order).toarray()
    reference = brute_force_gram(basis, order)
    scale = np.abs(reference).max()
    np.testing.assert_allclose(G, reference, atol=1e-12 * scale)
    # the Gram matrix sums products b_i b_j, symmetric up to the order of the sums:
    # round-off of a few ulps of its largest entry
    np.testing.assert_allclose(G, G.T, rtol=0, atol=1e-14 * scale)
    assert np.linalg.eigvalsh(G).min() > -1e-12 * scale


@SETTINGS
@given(basis=bases())
def test_row_sums_are_the_integrals_of_the_basis(basis):
    """Σ_l (G0)_kl = ∫ b_k Σ_l b_l = ∫ b_k, and Σ_k ∫ b_k = L."""
    G0 = gram_matrix(basis, 0)
    I = integrals(basis)
    np.testing.assert_allclose(np.asarray(G0.sum(axis=1)).ravel(), I, atol=1e-13 * basis.length)
    assert I.sum() == pytest.approx(basis.length, rel=1e-13)
    if basis.kind == "periodic":   # every periodic function is a whole B-spline: ∫ = h
        np.testing.assert_allclose(I, basis.h, rtol=1e-13)


@pytest.mark.parametrize("degree", [1, 2, 3, 4, 5])
def test_interior_entries_are_values_of_the_cardinal_spline_of_degree_2n_plus_1(degree):
    """∫ b^n(x/h - k) b^n(x/h - l) dx = h b^{2n+1}(n + 1 + k - l) for whole functions,
    and for derivatives ∫ D b_k D b_l = -h^{-1} D² b^{2n+1}(n + 1 + k - l)."""
    h, cells = 0.3, 3 * degree + 4
    basis = BSplineBasis(degree, cells, cells * h, "uniform")
    inner = np.arange(degree, cells)          # supports [(j-n) h, (j+1) h] inside [0, L]
    G0 = gram_matrix(basis, 0).toarray()[np.ix_(inner, inner)]
    G1 = gram_matrix(basis, 1).toarray()[np.ix_(inner, inner)]
    shift = inner[:, None] - inner[None, :]
    y = degree + 1.0 + shift
    np.testing.assert_allclose(G0, h * cardinal_bspline(y, 2 * degree + 1), atol=1e-14)
    second = (cardinal_bspline(y, 2 * degree - 1) - 2 * cardinal_bspline(y - 1, 2 * degree - 1)
              + cardinal_bspline(y - 2, 2 * degree - 1))
    np.testing.assert_allclose(G1, -second / h, atol=1e-12)


def test_cubic_gram_stencil_has_the_classical_values():
    """151/315, 397/1680, 1/42, 1/5040 (times h) for uniform cubic B-splines."""
    basis = BSplineBasis(3, 12, 6.0, "periodic")
    row = gram_matrix(basis, 0).toarray()[5] / basis.h
    np.testing.assert_allclose(row[2:9], [1 / 5040, 1 / 42, 397 / 1680, 151 / 315,
                                          397 / 1680, 1 / 42, 1 / 5040], rtol=1e-13)


def test_a_few_entries_against_adaptive_quadrature():
    basis = BSplineBasis(3, 4, 2.0, "open")
    breaks = list(np.arange(1, 4) * basis.h)
    G2 = gram_matrix(basis, 2).toarray()
    for k, l in [(0, 0), (0, 2), (1, 3), (3, 3), (6, 5)]:
        def integrand(x, k=k, l=l):
            row = basis([x], 2)[0]
            return row[k] * row[l]
        value, _ = quad(integrand, 0.0, 2.0, points=breaks, epsabs=1e-14, epsrel=1e-13)
        assert G2[k, l] == pytest.approx(value, rel=1e-10, abs=1e-12)


@SETTINGS
@given(basis=bases(degrees=(1, 5)))
def test_first_derivative_gram_annihilates_constants_only(basis):
    G1 = gram_matrix(basis, 1).toarray()
    scale = np.abs(G1).max()
    np.testing.assert_allclose(G1 @ np.ones(basis.size), 0.0, atol=1e-12 * scale * basis.size)
    eig = np.linalg.eigvalsh(G1)
    assert abs(eig[0]) < 1e-11 * scale
    assert eig[1] > 1e-8 * scale


@SETTINGS
@given(basis=bases(degrees=(2, 5)))
def test_second_derivative_gram_annihilates_linear_functions(basis):
    G2 = gram_matrix(basis, 2).toarray()
    scale = np.abs(G2).max()
    eig = np.linalg.eigvalsh(G2)
    tol = 1e-11 * scale * basis.size
    np.testing.assert_allclose(G2 @ np.ones(basis.size), 0.0, atol=tol)
    if basis.kind == "periodic":   # x is not periodic: only constants are in the null space
        assert abs(eig[0]) < tol and eig[1] > 1e-8 * scale
        return
    # x = Σ ξ_j b_j with the knot averages ξ_j (outside [0, L] at the ends for uniform knots)
    xi = knot_averages(basis)
    np.testing.assert_allclose(G2 @ xi, 0.0, atol=tol * max(1.0, basis.length))
    assert abs(eig[1]) < tol * max(1.0, basis.length) and eig[2] > 1e-8 * scale


@SETTINGS
@given(basis=bases(), order=st.integers(0, 2))
def test_gram_bandwidth_is_the_degree(basis, order):
    order = min(order, basis.degree)
    G = gram_matrix(basis, order).tocoo()
    distance = np.abs(G.row - G.col)
    if basis.kind == "periodic":
        distance = np.minimum(distance, basis.size - distance)
    assert distance.max() <= basis.degree
    enough = basis.size >= (2 * basis.degree + 1 if basis.periodic else basis.degree + 2)
    if order == 0 and enough:   # functions up to n apart overlap
        assert distance[np.abs(G.data) > 0].max() == basis.degree


def test_gauss_points_integrate_degree_2n_plus_1_exactly():
    basis = BSplineBasis(3, 5, 2.0, "open")
    x, w = gauss_points(basis)
    assert x.shape == w.shape == (20,)
    assert np.all(np.diff(x) > 0) and 0 < x.min() and x.max() < 2.0
    for p in range(8):   # ∫_0^2 x^p = 2^{p+1}/(p+1)
        assert w @ x**p == pytest.approx(2.0 ** (p + 1) / (p + 1), rel=1e-14)
    x6, w6 = gauss_points(basis, 6)
    assert x6.size == 30 and w6.sum() == pytest.approx(2.0, rel=1e-15)


@pytest.mark.parametrize("order", [-1, 4, 1.5])
def test_bad_order_says_what_is_allowed(order):
    with pytest.raises(InputError, match=r"integer in 0\.\.3"):
        gram_matrix(BSplineBasis(3, 4, 1.0, "open"), order)
