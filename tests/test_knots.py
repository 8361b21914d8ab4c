"""General knot vectors: agreement with the fast layouts, exact Gram matrices, bad input."""

import numpy as np
import pytest
from scipy.interpolate import splev

from splinedeform.basis import BSplineBasis
from splinedeform.errors import InputError
from splinedeform.knots import KnotVectorBasis, RationalBasis
from splinedeform.quadrature import gram_matrix, integrals

# Round-off tolerance: both paths evaluate the same polynomials with O(n) operations
# on numbers of size O(1/h^a); 1e-12 relative to the largest entry leaves margin.
TOL = 1e-12


def _close(a, b, tol=TOL):
    a = a.toarray() if hasattr(a, "toarray") else np.asarray(a)
    b = b.toarray() if hasattr(b, "toarray") else np.asarray(b)
    scale = max(1.0, float(np.abs(b).max()))
    np.testing.assert_allclose(a, b, rtol=0, atol=tol * scale)


@pytest.mark.parametrize("degree", [1, 2, 3, 5])
@pytest.mark.parametrize("kind", ["open", "uniform"])
def test_general_path_agrees_with_fast_layouts(degree, kind):
    fast = BSplineBasis(degree, 7, 2.5, kind)
    general = KnotVectorBasis(degree, fast.knots)
    assert general.size == fast.size and general.domain == (0.0, 2.5)
    x = np.linspace(0.0, 2.5, 61)
    for j in range(degree + 2):
        _close(general(x, j), fast(x, j))
    for a in range(degree + 1):
        _close(gram_matrix(general, a), gram_matrix(fast, a))
    _close(integrals(general), integrals(fast))


@pytest.mark.parametrize("degree", [2, 3])
def test_periodic_layout_is_wrapped_general_basis(degree):
    m = 6
    periodic = BSplineBasis(degree, m, 1.0, "periodic")
    uniform = KnotVectorBasis(degree, BSplineBasis(degree, m, 1.0, "uniform").knots)
    # function j of the uniform basis is function (j - n) mod m of the periodic one
    wrap = np.zeros((m + degree, m))
    wrap[np.arange(m + degree), np.mod(np.arange(m + degree) - degree, m)] = 1.0
    x = (np.arange(40) + 0.37) / 40   # off the knots: D^n jumps there (x = 1 wraps to 0)
    for j in range(degree + 1):
        _close(uniform(x, j) @ wrap, periodic(x, j))
    for a in range(degree + 1):
        _close(wrap.T @ gram_matrix(uniform, a).toarray() @ wrap, gram_matrix(periodic, a))


def _scipy_values(degree, knots, x, order):
    """``D^order N_k(x)`` from FITPACK's evaluator (one coefficient vector per function)."""
    size = len(knots) - degree - 1
    return np.stack([splev(x, (knots, np.eye(size + degree + 1)[k], degree), der=order)
                     for k in range(size)], axis=1)


def _scipy_gram(degree, knots, order):
    """Independent Gram matrix: scipy's B-spline evaluator, 2n+2 Gauss points per span."""
    breaks = np.unique(knots[degree:len(knots) - degree])
    gx, gw = np.polynomial.legendre.leggauss(2 * degree + 2)
    left, width = breaks[:-1, None], np.diff(breaks)[:, None]
    x = (left + 0.5 * width * (gx + 1)).ravel()
    w = (0.5 * width * gw).ravel()
    size = len(knots) - degree - 1
    values = _scipy_values(degree, knots, x, order).T
    return (values * w) @ values.T


@pytest.mark.parametrize("order", [0, 1, 2])
def test_gram_matrix_of_nonuniform_knots_with_multiplicities(order):
    knots = np.array([0, 0, 0, 0, 0.1, 0.35, 0.35, 0.5, 0.9, 0.9, 0.9, 1.7, 2, 2, 2, 2.0])
    basis = KnotVectorBasis(3, knots)
    _close(gram_matrix(basis, order), _scipy_gram(3, knots, order))
    if order == 0:  # Σ_k N_k = 1, so Σ_kl G0_kl = ∫ 1 = length of the domain
        assert abs(gram_matrix(basis, 0).sum() - 2.0) <= 1e-13
    else:           # D^a of a constant vanishes
        assert np.abs(gram_matrix(basis, order) @ np.ones(basis.size)).max() <= 1e-10


def test_values_match_scipy_on_nonuniform_knots():
    knots = np.array([-1, -1, -1, -0.2, -0.2, 0.4, 3, 3, 3.0])
    basis = KnotVectorBasis(2, knots)
    x = np.linspace(-1, 3, 57)
    for j in range(3):
        _close(basis(x, j), _scipy_values(2, knots, x, j))


@pytest.mark.parametrize("degree, knots, message", [
    (0, [0, 1], "degree"),
    (2, [0, 0, 1, 1], "at least 6 knots"),
    (2, [0, 0, 0, 1, 0.5, 1, 1], "non-decreasing"),
    (2, [0, 0, 0, 0.5, 0.5, 0.5, 1, 1, 1], "repeated 3 times"),
    (2, [0, 0, 0, 0, 0, 0, 1], "at least|empty domain"),
])
def test_bad_knot_vectors_are_refused(degree, knots, message):
    with pytest.raises(InputError, match=message):
        KnotVectorBasis(degree, knots)


def test_parameters_outside_the_domain_are_refused():
    with pytest.raises(InputError, match="outside the domain"):
        KnotVectorBasis(2, [0, 0, 0, 1, 1, 1])([1.5])


QUARTER = KnotVectorBasis(2, [0, 0, 0, 1, 1, 1])
CIRCLE_POINTS = np.array([[1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])


def test_rational_quarter_circle_is_exact():
    # exact NURBS circle: radius 1 up to round-off of a few operations (1e-12 leaves margin)
    r = RationalBasis(QUARTER, [1.0, np.sqrt(0.5), 1.0])
    x = np.linspace(0.0, 1.0, 10_000)
    point, tangent, second = (r(x, j) @ CIRCLE_POINTS for j in range(3))
    assert np.abs(np.hypot(*point.T) - 1.0).max() <= 1e-12
    # first and second derivatives checked against the circle: p·p' = 0, p·p'' = -|p'|²
    assert np.abs((point * tangent).sum(1)).max() <= 1e-12
    curvature_check = (point * second).sum(1) + (tangent ** 2).sum(1)
    assert np.abs(curvature_check).max() <= 1e-11 * (tangent ** 2).sum(1).max()


@pytest.mark.parametrize("order", [0, 1, 2])
def test_rational_basis_with_equal_weights_is_the_polynomial_basis(order):
    knots = [0, 0, 0, 0, 0.3, 0.3, 1, 1, 1, 1]
    poly = KnotVectorBasis(3, knots)
    rational = RationalBasis(poly, np.full(poly.size, 2.5))
    _close(gram_matrix(rational, order), gram_matrix(poly, order))


def test_rational_gram_converges_under_quadrature_refinement():
    # R_k is rational, so Gauss–Legendre converges geometrically instead of being exact:
    # measured relative errors of G2 for 4, 6, 8, 10, 12 points: 2e-3, 2e-5, 1e-7, 4e-10, 1e-12
    w = [1.0, np.sqrt(0.5), 1.0]
    reference = gram_matrix(RationalBasis(QUARTER, w, points_per_cell=60), 2).toarray()
    scale = np.abs(reference).max()
    errors = [np.abs(gram_matrix(RationalBasis(QUARTER, w, points_per_cell=q), 2).toarray()
                     - reference).max() / scale for q in (4, 6, 8, 10, 12)]
    assert all(b <= a / 50 for a, b in zip(errors, errors[1:]))
    # default rule (2n+10 = 14 points): round-off level; 1e-13 leaves margin over ~1e-15
    assert np.abs(gram_matrix(RationalBasis(QUARTER, w), 2).toarray()
                  - reference).max() <= 1e-13 * scale


def test_bad_weights_are_refused():
    with pytest.raises(InputError, match="3 weights"):
        RationalBasis(QUARTER, [1.0, 1.0])
    with pytest.raises(InputError, match="> 0"):
        RationalBasis(QUARTER, [1.0, 0.0, 1.0])


def test_docs_cad_code_blocks_run(capsys, tmp_path, monkeypatch):
    """The first block of docs/cad.md (the knot vectors), its printed figures checked; the
    others run in tests/test_docs.py. In a scratch folder: a block may write files."""
    import pathlib
    import re
    text = (pathlib.Path(__file__).parents[1] / "docs" / "cad.md").read_text()
    blocks = re.findall(r"```python\n(.*?)```", text, flags=re.S)
    assert blocks
    monkeypatch.chdir(tmp_path)
    exec(compile(blocks[0], "docs/cad.md", "exec"), {})
    out = capsys.readouterr().out
    assert float(out.split()[2]) <= 1e-12       # exact circle: round-off only
    assert abs(float(out.split()[3]) - 1.0) <= 1e-13   # Σ G0 = domain length 1
