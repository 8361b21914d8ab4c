"""WEB-spline index sets, extension coefficients and conditioning under moving trim loops."""

import numpy as np
import pytest

from splinedeform.errors import InputError
from splinedeform.trim import INSIDE, CircleLoop, Grid, TrimDomain, classify_cells
from splinedeform.trim.plate import assemble_plate
from splinedeform.trim.web import lagrange_coefficients, web_basis
from splinedeform.trim.weight import DiscWeight


@pytest.mark.parametrize("degree", [2, 3, 4])
def test_extension_reproduces_polynomial_coefficients(degree):
    # uniform B-splines reproduce polynomials of degree <= n with coefficients that are
    # polynomials of degree <= n in the index, so Lagrange extrapolation from the inner
    # coefficients gives the outer ones exactly; 1e-9 relative allows the round-off of
    # extrapolating over a few indices (coefficients up to ~1e3)
    classes = classify_cells(TrimDomain(CircleLoop((0.5, 0.47), 0.36)), Grid((9, 9)))
    web = web_basis(classes, degree)
    k1, k2 = np.meshgrid(*(np.arange(s, dtype=float) for s in web.inner.shape), indexing="ij")
    coeff = (1 + 0.3 * k1 - 0.2 * k2) ** degree + k1 ** degree * 0.1 - 2 * k2 ** (degree - 1)
    extended = web.extension @ coeff[web.inner]
    outer = web.outer.ravel()
    scale = np.abs(coeff).max()
    assert np.max(np.abs(extended[outer] - coeff.ravel()[outer])) < 1e-9 * scale
    # the inner rows of the extension are unit rows: each inner coefficient comes back
    # from a sparse product with one entry 1, to 1e-14 relative (a few units in the last
    # place should another product sum rounded zeros)
    assert np.max(np.abs(extended[web.inner.ravel()] - coeff[web.inner])) <= 1e-14 * scale


def test_index_sets_follow_the_cells():
    n = 3
    classes = classify_cells(TrimDomain(CircleLoop((0.5, 0.5), 0.3)), Grid((8, 8)))
    web = web_basis(classes, n)
    for k1, k2 in np.argwhere(web.inner):
        cells = classes[max(k1 - n, 0):k1 + 1, max(k2 - n, 0):k2 + 1]
        assert np.any(cells == INSIDE)
    for k1, k2 in np.argwhere(web.outer):
        cells = classes[max(k1 - n, 0):k1 + 1, max(k2 - n, 0):k2 + 1]
        assert not np.any(cells == INSIDE) and np.any(cells != 0)


def test_lagrange_coefficients_are_a_partition_of_unity_and_interpolate():
    L = lagrange_coefficients(np.array([-2.0, 0.0, 1.0, 5.5]), 3)
    assert np.allclose(L.sum(axis=-1), 1.0, atol=1e-12)   # constants reproduced, round-off
    # at the nodes t = 0, 1 the coefficients are unit vectors: exact products, 1e-12 round-off
    assert np.allclose(L[1], [1, 0, 0, 0], rtol=0, atol=1e-12)
    assert np.allclose(L[2], [0, 1, 0, 0], rtol=0, atol=1e-12)


def test_too_coarse_a_grid_is_refused():
    classes = classify_cells(TrimDomain(CircleLoop((0.5, 0.5), 0.2)), Grid((3, 3)))
    with pytest.raises(InputError, match="refine the grid"):
        web_basis(classes, 3)


def _cond(matrix):
    """Spectral condition number ``λ_max / λ_min`` of a symmetric positive definite matrix."""
    eigenvalues = np.linalg.eigvalsh(matrix.toarray())
    return float(eigenvalues[-1] / eigenvalues[0])


def test_conditioning_bounded_as_a_loop_moves_through_a_cell():
    # the circle grows past the grid line u = 0.875 in steps of 1e-6: new B-splines meet
    # the region in slivers of width ~1e-6. WEB mass and stiffness keep their condition
    # numbers (changes ~1e-4 relative, 1 % allowed); the plain weighted basis degenerates
    webs, plain = [], []
    for k in range(4):
        r = 0.375 + k * 1e-6
        domain, weight = TrimDomain(CircleLoop((0.5, 0.5), r)), DiscWeight((0.5, 0.5), r, 1)
        plate = assemble_plate(domain, 8, 3, weight)
        webs.append((_cond(plate.mass), _cond(plate.stiffness)))
        if k == 1:
            eigenvalues = np.linalg.eigvalsh(
                assemble_plate(domain, 8, 3, weight, extended=False).mass.toarray())
            plain.append(abs(eigenvalues[0]) / eigenvalues[-1])   # round-off may flip its sign
    mass, stiffness = np.array(webs).T
    assert mass.max() / mass.min() < 1.01 and stiffness.max() / stiffness.min() < 1.01
    assert mass.max() < 1e6 and plain[0] < 1e-12


def test_conditioning_under_refinement_grows_as_for_an_untrimmed_net():
    # halving h multiplies cond(K) of a fourth-order problem by at most ~2^4 = 16 (factor 2
    # allowed for the pre-asymptotic range; measured 2.8 from 10 to 20 cells); cond(M)
    # stays below a bound independent of h (Höllig's stability; measured 1e5 .. 9e5 for
    # 8 .. 40 cells, depending on how the circle cuts the cells)
    r = 0.3751
    domain, weight = TrimDomain(CircleLoop((0.5, 0.5), r)), DiscWeight((0.5, 0.5), r, 1)
    (m_c, k_c), (m_f, k_f) = [(_cond(p.mass), _cond(p.stiffness))
                              for p in (assemble_plate(domain, m, 3, weight) for m in (10, 20))]
    assert k_f / k_c < 32
    assert max(m_c, m_f) < 2e6


def _open_knots(breaks, degree):
    return np.r_[[breaks[0]] * degree, breaks, [breaks[-1]] * degree]


@pytest.mark.parametrize("degrees", [(3, 3), (2, 4)])
def test_the_polar_form_extends_polynomials_on_general_knots(degrees):
    # Marsden: a polynomial of degree (n_u, n_v) lies in the span of the B-splines of any
    # knot vectors, with coefficients its polar forms; found here independently by
    # collocation at the Greville abscissae, then the outer ones are compared with the
    # extension of the inner ones. The knots are unequal (breaks drawn at random) and
    # clamped; the classes of a 9 × 9 grid are index tables only, so any breaks with 9
    # cells serve. 1e-9 of the largest coefficient: collocation and extrapolation over a
    # few indices in floating point (measured ~1e-12)
    from splinedeform.knots import KnotVectorBasis

    rng = np.random.default_rng(7)
    classes = classify_cells(TrimDomain(CircleLoop((0.5, 0.47), 0.36)), Grid((9, 9)))
    knots, coeffs = [], []
    for n in degrees:
        breaks = np.r_[0.0, np.sort(rng.uniform(0.05, 0.95, 8)), 1.0]
        t = _open_knots(breaks, n)
        basis = KnotVectorBasis(n, t)
        greville = np.array([t[k + 1:k + n + 1].mean() for k in range(len(t) - n - 1)])
        knots.append(t)
        coeffs.append((basis, greville))
    (bu, gu), (bv, gv) = coeffs
    x, y = np.meshgrid(gu, gv, indexing="ij")
    n_u, n_v = degrees
    values = (1 + 0.3 * x) ** n_u * (2 - y) ** n_v + x ** n_u - 2 * y ** (n_v - 1)
    Au, Av = bu(gu), bv(gv)
    coeff = np.linalg.solve(Au, np.linalg.solve(Av, values.T).T)
    web = web_basis(classes, degrees, knots=tuple(knots))
    extended = web.extension @ coeff[web.inner]
    outer = web.outer.ravel()
    assert outer.any()
    scale = np.abs(coeff).max()
    assert np.max(np.abs(extended[outer] - coeff.ravel()[outer])) < 1e-9 * scale


def test_the_polar_form_on_uniform_knots_is_lagrange_in_the_index():
    # the two formulas of the extension agree where both hold; 1e-10 absolute on
    # coefficients of size up to ~1e2 (extrapolation a few indices out), round-off
    from splinedeform.basis import BSplineBasis

    classes = classify_cells(TrimDomain(CircleLoop((0.5, 0.5), 0.33)), Grid((8, 8)))
    t = BSplineBasis(3, 8, 1.0, "uniform").knots
    plain = web_basis(classes, 3).extension.toarray()
    polar = web_basis(classes, 3, knots=(t, t)).extension.toarray()
    assert np.abs(plain - polar).max() < 1e-10
