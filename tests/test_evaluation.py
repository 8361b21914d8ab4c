"""Surface evaluation as a user calls it (Bézier patches, one point) against scipy's NdBSpline."""

import numpy as np
import pytest
from scipy.interpolate import NdBSpline

from splinedeform.basis import BSplineBasis
from splinedeform.errors import InputError
from splinedeform.knots import KnotVectorBasis
from splinedeform.surface import Surface

ORDERS = [(0, 0), (1, 0), (0, 1), (1, 1), (2, 0), (0, 2), (2, 1), (3, 3)]


def surface_on(bu, bv, seed=0):
    return Surface(np.random.default_rng(seed).normal(size=(bu.size, bv.size, 3)), bu, bv)


def reference(surface):
    bu, bv = surface.basis_u, surface.basis_v
    return NdBSpline((bu.knots, bv.knots), surface.control_points, (bu.degree, bv.degree))


SURFACES = {
    "open cubic x quadratic": (BSplineBasis(3, 6, 2.0, "open"), BSplineBasis(2, 5, 1.0, "open")),
    "uniform quartic x cubic": (BSplineBasis(4, 5, 1.5, "uniform"),
                                BSplineBasis(3, 7, 1.0, "uniform")),
    "non-uniform knots with a double knot": (
        KnotVectorBasis(3, [0, 0, 0, 0, 0.1, 0.35, 0.35, 0.6, 1.2, 1.2, 1.2, 1.2]),
        BSplineBasis(3, 4, 1.0, "open")),
}


@pytest.mark.parametrize("name", SURFACES)
def test_pointwise_and_one_point_evaluation_equal_ndbspline(name):
    """Every order up to (3, 3) at random points, at the knots and at the domain's corners.

    NdBSpline runs de Boor's recurrence in compiled code: an independent evaluation. The
    goal is 1e-13 relative to the largest value of the order (sums of O((n+1)²) roundings).
    """
    s = surface_on(*SURFACES[name])
    spline = reference(s)
    rng = np.random.default_rng(3)
    (_, Lu), (_, Lv) = s.domain
    knots_u = np.unique(np.clip(s.basis_u.knots, 0, Lu))
    u = np.concatenate([rng.uniform(0, Lu, 300), knots_u, [0.0, Lu, Lu]])
    v = np.concatenate([rng.uniform(0, Lv, 300 + knots_u.size), [Lv, 0.0, Lv]])
    for du, dv in ORDERS:
        expected = spline(np.stack([u, v], -1), nu=(du, dv))
        scale = np.abs(expected).max()
        np.testing.assert_allclose(s.derivative(u, v, du, dv), expected, rtol=0,
                                   atol=1e-13 * scale)
        for a, b in zip(u[::37], v[::37]):
            one = s.derivative(float(a), float(b), du, dv)
            assert one.shape == (3,)
            np.testing.assert_allclose(one, spline([a, b], nu=(du, dv)), rtol=0,
                                       atol=1e-13 * scale)
    np.testing.assert_allclose(s.evaluate(0.3, 0.7), spline([0.3, 0.7]), rtol=0,
                               atol=1e-13 * np.abs(s.control_points).max())


def test_patches_agree_with_the_sum_over_the_control_points_on_a_periodic_net():
    """A periodic direction has no NdBSpline; the B-spline sum on another net is the reference."""
    s = surface_on(BSplineBasis(3, 6, 2.0, "open"), BSplineBasis(3, 5, 1.0, "periodic"), 4)
    u = np.random.default_rng(5).uniform(0, 2, 200)
    v = np.random.default_rng(6).uniform(-1, 3, 200)           # periodic: any v
    for du, dv in ORDERS:
        by_patches = s.derivative(u, v, du, dv)
        by_sum = s.derivative(u, v, du, dv, control_points=s.control_points)
        # both sum O((n+1)²) products of values bounded by the order's largest: 1e-13
        np.testing.assert_allclose(by_patches, by_sum, rtol=0,
                                   atol=1e-13 * max(np.abs(by_sum).max(), 1.0))
        np.testing.assert_allclose(s.derivative(float(u[0]), float(v[0]), du, dv),
                                   by_sum[0], rtol=0, atol=1e-13 * max(np.abs(by_sum).max(), 1.0))


def test_values_at_knots_are_exact_where_the_bsplines_vanish():
    """At a knot the B-splines that start or end there are exactly 0, not a rounding error."""
    for kind in ("open", "uniform", "periodic"):
        basis = BSplineBasis(3, 6, 6.0, kind)                 # knots at the integers
        values = basis.nonzero(np.arange(7.0))[1]
        assert np.all(values[:-1, -1] == 0.0)                 # starts at its cell's left knot
        if kind != "periodic":                                # (periodic: L is 0 again)
            assert values[-1, 0] == 0.0                       # ends at L (last cell closed)
        if kind == "open":                                    # interpolates its corner point
            s = surface_on(basis, basis)
            # the last B-spline is 1 there up to the rounding of the recurrence (a few
            # units in the last place): 1e-14 of the net's size
            size = np.abs(s.control_points).max()
            np.testing.assert_allclose(s.evaluate(6.0, 6.0), s.control_points[-1, -1],
                                       rtol=0, atol=1e-14 * size)


def test_one_point_outside_the_domain_or_not_finite_is_refused():
    s = surface_on(BSplineBasis(3, 6, 2.0, "open"), BSplineBasis(2, 5, 1.0, "open"))
    with pytest.raises(InputError, match=r"outside the domain \[0, 2\]"):
        s.evaluate(2.5, 0.5)
    with pytest.raises(InputError, match="finite"):
        s.evaluate(float("nan"), 0.5)
    with pytest.raises(InputError, match="finite"):
        s.evaluate(0.5, float("inf"))
    # a rounding error beyond the end is the end: the same point, to 1e-14 of the net's
    # size (what a parameter 1e-15 inside would move it by is far below that)
    np.testing.assert_allclose(s.evaluate(2.0 + 1e-15, 0.5), s.evaluate(2.0, 0.5), rtol=0,
                               atol=1e-14 * np.abs(s.control_points).max())
    with pytest.raises(InputError, match="derivative order"):
        s.derivative(0.5, 0.5, -1, 0)


def test_patches_are_built_once_as_many_points_as_cells_were_asked_for():
    """One point on a new surface goes the direct way; the patches come with enough points."""
    s = surface_on(BSplineBasis(3, 6, 2.0, "open"), BSplineBasis(2, 5, 1.0, "open"))
    spline = reference(s)
    direct = s.evaluate(0.3, 0.7)
    assert ("patches", 0, 0) not in s._cache                 # a single point builds nothing
    u = np.linspace(0.0, 2.0, 29)                            # 29 + 1 = 30 = 6 x 5 cells
    s.evaluate(u, np.full_like(u, 0.4))
    assert s._cache[("patches", 0, 0)] is not None
    by_patches = s.evaluate(0.3, 0.7)
    scale = np.abs(s.control_points).max()
    # two summation orders of the same O((n+1)²) terms, and scipy's: 1e-13 of the net's size
    np.testing.assert_allclose(by_patches, direct, rtol=0, atol=1e-13 * scale)
    np.testing.assert_allclose(direct, spline([0.3, 0.7]), rtol=0, atol=1e-13 * scale)


@pytest.mark.parametrize("name", SURFACES)
def test_one_point_on_a_new_surface_equals_ndbspline_for_every_order(name):
    """The direct way (no patches yet): the cell's (n+1)² control points, every order."""
    bu, bv = SURFACES[name]
    for du, dv in ORDERS:
        s = surface_on(bu, bv, seed=7)                       # new: no patches
        expected = reference(s)([0.37, 0.61], nu=(du, dv))
        got = s.derivative(0.37, 0.61, du, dv)
        assert ("patches", du, dv) not in s._cache
        # 1e-13 of the order's scale (the net's size times the basis derivatives' scale)
        scale = max(np.abs(expected).max(), np.abs(s.control_points).max())
        np.testing.assert_allclose(got, expected, rtol=0, atol=1e-13 * scale)


def test_one_point_on_a_new_periodic_surface_equals_the_array_path():
    s = surface_on(BSplineBasis(3, 6, 2.0, "open"), BSplineBasis(3, 5, 1.0, "periodic"), 4)
    for du, dv in ORDERS:
        by_sum = s.derivative(np.array([1.3]), np.array([2.9]), du, dv,
                              control_points=s.control_points)[0]
        fresh = s.with_control_points(s.control_points)
        np.testing.assert_allclose(fresh.derivative(1.3, 2.9, du, dv), by_sum, rtol=0,
                                   atol=1e-13 * max(np.abs(by_sum).max(), 1.0))


@pytest.mark.parametrize("samples", [(4, 3), (200, 150)])
@pytest.mark.parametrize("shared", [True, False])
def test_grid_evaluation_equals_ndbspline_by_gather_and_by_sparse_product(samples, shared):
    """``evaluate_grid`` against NdBSpline on the grid's points, for small grids (the rows
    gathered and contracted) and larger ones (scipy's sparse product), with one basis
    shared by both directions (evaluated once) and with two bases.

    Both paths and scipy sum the same ``(n+1)²`` products in other orders: 1e-13 relative
    to the largest value of the order, as for the pointwise evaluation.
    """
    from splinedeform import collocation
    basis = BSplineBasis(3, 9, 1.0, "open")
    other = basis if shared else BSplineBasis(2, 7, 1.0, "open")
    s = surface_on(basis, other, seed=4)
    u, v = np.linspace(0.0, 1.0, samples[0]), np.linspace(0.0, 1.0, samples[1])
    # the numbers each product would gather: N_u (n+1) n_v 3, then N_v (n+1) N_u 3
    sizes = (samples[0] * 4 * other.size * 3, samples[1] * (other.degree + 1) * samples[0] * 3)
    small = samples == (4, 3)
    assert all((size <= collocation.GATHER_LIMIT) == small for size in sizes)
    U, V = np.meshgrid(u, v, indexing="ij")
    points = np.stack([U.ravel(), V.ravel()], axis=-1)
    for du, dv in [(0, 0), (1, 0), (0, 2), (1, 1)]:
        expected = reference(s)(points, nu=(du, dv)).reshape(U.shape + (3,))
        grid = s.evaluate_grid(u, v, du, dv)
        scale = float(np.abs(expected).max())
        np.testing.assert_allclose(grid, expected, rtol=0, atol=1e-13 * scale)
    # a scalar field on the net: records of one number
    field = s.control_points[..., :1]
    np.testing.assert_allclose(s.evaluate_grid(u, v, control_points=field)[..., 0],
                               s.evaluate_grid(u, v)[..., 0], rtol=0, atol=1e-15 * scale)
