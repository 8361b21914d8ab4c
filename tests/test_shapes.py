"""Fitting control nets and the built-in shapes: exactness, convergence rates, closure, errors."""

from math import pi

import numpy as np
import pytest

import splinedeform as sd
from splinedeform import shapes
from splinedeform.basis import BSplineBasis
from splinedeform.errors import InputError
from splinedeform.surface import Surface

METHODS = ("interpolate", "l2", "quasi")


def grid_error(surface, f, per_cell=7, origin=(0.0, 0.0)):
    """Max distance on a sample not aligned with any fitting nodes (7 points per cell)."""
    u = np.linspace(0.0, surface.basis_u.length, per_cell * surface.basis_u.cells + 1)
    v = np.linspace(0.0, surface.basis_v.length, per_cell * surface.basis_v.cells + 1)
    U, V = np.meshgrid(u + origin[0], v + origin[1], indexing="ij")
    return float(np.linalg.norm(surface.evaluate_grid(u, v) - f(U, V), axis=-1).max())


def rates(errors):
    errors = np.asarray(errors)
    return np.log2(errors[:-1] / errors[1:])


def sphere_map(R):
    def f(u, v):
        phi, theta = u / R, v / R
        return R * np.stack([np.cos(theta) * np.cos(phi), np.cos(theta) * np.sin(phi),
                             np.sin(theta)], -1)
    return f


def smooth_map(u, v):
    return np.stack([u + 0.1 * np.sin(v), v, np.exp(u) * np.sin(2 * v)], -1)


# -- exactness ------------------------------------------------------------------------------
@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("knots", ["open", "uniform"])
@pytest.mark.parametrize("degree", [2, 3, 4])
def test_plane_and_saddle_are_reproduced_exactly(method, knots, degree):
    Lu, Lv, h = 2.0, 1.5, 0.3
    plane = shapes.plane(size=(Lu, Lv), cells=(5, 4), degree=degree, knots=knots, method=method)
    saddle = shapes.saddle(size=(Lu, Lv), height=h, cells=(3, 4), degree=degree, knots=knots,
                           method=method)
    assert plane.fit_error < 1e-12 and saddle.fit_error < 1e-12
    assert plane.domain == ((0.0, Lu), (0.0, Lv)) and saddle.domain == ((0.0, Lu), (0.0, Lv))
    u, v = np.random.default_rng(degree).uniform(0, 1, (2, 40)) * [[Lu], [Lv]]
    np.testing.assert_allclose(plane.evaluate(u, v), np.stack([u, v, 0 * u], -1), atol=1e-12)
    xi, eta = 2 * u / Lu - 1, 2 * v / Lv - 1
    exact = np.stack([u - Lu / 2, v - Lv / 2, h * (xi**2 - eta**2)], -1)
    np.testing.assert_allclose(saddle.evaluate(u, v), exact, atol=1e-12)
    np.testing.assert_allclose(plane.normal(u, v), np.broadcast_to([0, 0, 1.0], (40, 3)),
                               atol=1e-12)


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("knots", ["open", "uniform"])
@pytest.mark.parametrize("degree", [1, 2, 3])
def test_plane_net_is_the_fit_of_every_method(method, knots, degree):
    """The plane's net is built, not fitted: it equals what each fitting method makes of
    the map ``(u, v, 0)``, an independent computation. Tolerance 1e-10 of the side
    length: both are exact up to rounding, the fits through a linear solve (the L2
    projection's Gram system on uniform knots loses most, 6e-12 at degree 3; at degree 5
    its outer functions barely reach into ``[0, L]`` and it loses 3e-7, so the test stops
    at cubics)."""
    size, cells = (2.0, 1.5), (7, 4)
    surf = shapes.plane(size=size, cells=cells, degree=degree, knots=knots, method=method)
    fitted = shapes.fit_control_points(lambda u, v: np.stack([u, v, 0 * u], -1),
                                       surf.basis_u, surf.basis_v, method)
    np.testing.assert_allclose(surf.control_points, fitted, rtol=0, atol=1e-10 * max(size))
    assert surf.fit_error == 0.0


@pytest.mark.parametrize("method", METHODS)
def test_linear_plane_is_exact_for_degree_one(method):
    surf = shapes.plane(size=3.0, cells=4, degree=1, method=method)
    assert surf.fit_error < 1e-13 and surf.shape == (5, 5)
    assert surf.domain == ((0.0, 3.0), (0.0, 3.0))


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("knots", ["open", "uniform", "periodic"])
@pytest.mark.parametrize("degree", [1, 2, 3, 4])
def test_every_method_reproduces_every_spline_of_the_space(method, knots, degree):
    """Interpolation, L2 projection and the quasi-interpolant are projectors onto the space:
    a map that is itself such a spline comes back with the same control points."""
    bu = BSplineBasis(degree, degree + 3, 1.3, knots)
    bv = BSplineBasis(degree, degree + 2, 0.8, "open")
    P = np.random.default_rng(degree).normal(size=(bu.size, bv.size, 3))
    source = Surface(P, bu, bv)
    fitted = shapes.from_function(source.evaluate, cells=(bu.cells, bv.cells), degree=degree,
                                  knots=(knots, "open"), domain=((0, 1.3), (0, 0.8)),
                                  method=method)
    np.testing.assert_allclose(fitted.control_points, P, atol=1e-10)
    assert fitted.fit_error < 1e-11 and fitted.name == "function"


@pytest.mark.parametrize("knots", ["open", "uniform"])
@pytest.mark.parametrize("degree", [2, 3, 4, 5])
def test_quasi_interpolant_has_full_polynomial_precision(knots, degree):
    """Every polynomial of degree <= n in each variable is reproduced."""
    c = np.random.default_rng(degree).normal(size=(degree + 1, degree + 1, 3))

    def poly(u, v):
        return np.einsum("ijc,...i,...j->...c", c, u[..., None] ** np.arange(degree + 1),
                         v[..., None] ** np.arange(degree + 1))

    surf = shapes.from_function(poly, cells=(4, 3), degree=degree, knots=knots,
                                domain=((-1, 1), (0, 1)), method="quasi")
    assert grid_error(surf, poly, origin=(-1.0, 0.0)) < 1e-11 * np.abs(c).sum()


@pytest.mark.parametrize("kind", ["open", "uniform", "periodic"])
@pytest.mark.parametrize("degree", [1, 2, 3, 4])
def test_quasi_weights_are_local_and_sum_to_one(kind, degree):
    basis = BSplineBasis(degree, 8, 2.0, kind)
    W, nodes = shapes.quasi_weights(basis)
    np.testing.assert_allclose(np.asarray(W.sum(axis=1)).ravel(), 1.0, atol=1e-12)
    assert W.getnnz(axis=1).max() <= 2 * degree + 1
    assert nodes.min() >= 0 and nodes.max() <= 2.0 and np.all(np.diff(nodes) > 0)
    # locality: the nodes of row k span at most n+1 cells and meet the support of b_k,
    # [(k-n) h, (k+1) h] (modulo L when periodic)
    h, dense = basis.h, W.toarray()
    for k in range(basis.size):
        at = nodes[dense[k] != 0]
        if kind == "periodic":
            at = np.mod(at - k * h + 0.5 * h, 2.0) + k * h - 0.5 * h   # unwrap near k h
            low, high = k * h, (k + degree + 1) * h
        else:
            low, high = (k - degree) * h, (k + 1) * h
        assert at.max() - at.min() <= (degree + 1) * h + 1e-12
        assert min(at.max(), high) - max(at.min(), low) >= -1e-12


def test_interior_periodic_cubic_rule_is_symmetric_with_a_small_norm():
    basis = BSplineBasis(3, 16, 16.0, "periodic")    # h = 1
    W, nodes = shapes.quasi_weights(basis)
    row = W.toarray()[5]
    weights, at = row[row != 0], nodes[row != 0]
    centre = 5 + 2.0                                  # support [5, 9]
    np.testing.assert_allclose(at - centre, -(at - centre)[::-1], atol=1e-13)
    np.testing.assert_allclose(weights, weights[::-1], atol=1e-13)
    assert np.abs(weights).sum() < 4.0


# -- convergence -------------------------------------------------------------------------
@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("knots", [("periodic", "open"), ("open", "open"),
                                   ("uniform", "uniform")])
def test_half_sphere_error_falls_at_order_n_plus_one(method, knots):
    R, degree = 1.3, 3
    errors = [grid_error(shapes.half_sphere(radius=R, cells=(2 * c, c), degree=degree,
                                            knots=knots, method=method), sphere_map(R))
              for c in (4, 8, 16, 32)]
    assert min(rates(errors)) >= degree + 1 - 0.3, (errors, rates(errors))


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("knots", ["open", "uniform"])
@pytest.mark.parametrize("degree", [2, 4])
def test_smooth_map_error_falls_at_order_n_plus_one(method, knots, degree):
    domain = ((0.5, 1.5), (-1.0, 0.5))
    errors = [grid_error(shapes.from_function(smooth_map, cells=(c, c), degree=degree,
                                              knots=knots, domain=domain, method=method),
                         smooth_map, origin=(0.5, -1.0))
              for c in (4, 8, 16, 32)]
    assert min(rates(errors)[1:]) >= degree + 1 - 0.3, (errors, rates(errors))
    assert errors[-1] < 1e-4


# -- the built-in shapes ----------------------------------------------------------------------
def test_fit_error_is_the_max_distance_on_four_samples_per_cell():
    surf = shapes.tile(radius=1.5, angle=1.2, length=2.0, cells=(3, 2), degree=2)
    R = 1.5

    def f(u, v):
        phi = u / R - 0.6
        return np.stack([R * np.sin(phi), v, R * np.cos(phi)], -1)

    u, v = np.linspace(0, R * 1.2, 13), np.linspace(0, 2.0, 9)
    U, V = np.meshgrid(u, v, indexing="ij")
    expected = np.linalg.norm(surf.evaluate_grid(u, v) - f(U, V), axis=-1).max()
    assert surf.fit_error == pytest.approx(expected, rel=1e-12)
    assert surf.fit_error > 1e-5     # a circle is not a polynomial


def test_tile_lies_on_its_cylinder_with_the_crest_on_top():
    R, angle, length = 2.0, pi / 2, 3.0
    surf = shapes.tile(radius=R, angle=angle, length=length, cells=(8, 2))
    assert surf.name == "tile" and surf.domain == ((0.0, R * angle), (0.0, length))
    u, v = np.linspace(0, R * angle, 21), np.linspace(0, length, 5)
    X = surf.evaluate_grid(u, v)
    assert np.abs(np.hypot(X[..., 0], X[..., 2]) - R).max() <= surf.fit_error + 1e-12
    np.testing.assert_allclose(X[..., 1], np.broadcast_to(v, (21, 5)), atol=1e-12)
    np.testing.assert_allclose(X[10, 0], [0.0, 0.0, R], atol=1e-12)        # the crest
    np.testing.assert_allclose(X[0, 0], [-R * np.sin(angle / 2), 0, R * np.cos(angle / 2)],
                               atol=1e-12)                                  # open knots: ends
    n = surf.normal(u[:, None], v[None, :])
    radial = X / np.hypot(X[..., 0], X[..., 2])[..., None] * [1, 0, 1]
    assert np.all(np.sum(n * radial, axis=-1) > 0.999)                   # outwards


def test_half_sphere_rim_pole_and_normals():
    R = 1.3
    surf = shapes.half_sphere(radius=R)
    assert surf.name == "half_sphere" and surf.shape == (16, 11)
    assert surf.basis_u.kind == "periodic" and surf.basis_v.kind == "open"
    np.testing.assert_allclose(surf.domain, ((0.0, 2 * pi * R), (0.0, pi * R / 2)))
    assert surf.fit_error < 1e-3 * R
    u = np.linspace(0, 2 * pi * R, 41)
    rim = surf.evaluate(u, 0.0)                       # v = 0: the equator z = 0
    np.testing.assert_allclose(rim[:, 2], 0.0, atol=1e-12)
    assert np.abs(np.hypot(rim[:, 0], rim[:, 1]) - R).max() <= surf.fit_error
    P = surf.control_points
    np.testing.assert_allclose(P[:, -1], np.broadcast_to([0, 0, R], P[:, -1].shape),
                               atol=1e-12)            # the pole row collapses onto the pole
    with pytest.raises(InputError, match="degenerate"):
        surf.normal(1.0, pi * R / 2)
    U, V = np.meshgrid(u, np.linspace(0, 0.9 * pi * R / 2, 7), indexing="ij")
    X = surf.evaluate(U, V)
    assert np.abs(np.linalg.norm(X, axis=-1) - R).max() <= surf.fit_error
    cosines = np.sum(surf.normal(U, V) * X, -1) / np.linalg.norm(X, axis=-1)
    assert cosines.min() > 0.99                       # x_u × x_v points outwards


def seam_check(surf, direction, exact):
    """Value and first derivative agree across the seam and with the exact map."""
    L = (surf.basis_u if direction == 0 else surf.basis_v).length
    other = np.linspace(0, (surf.basis_v if direction == 0 else surf.basis_u).length, 9)
    at = (lambda s: (s, other)) if direction == 0 else (lambda s: (other, s))
    d = (1, 0) if direction == 0 else (0, 1)
    for order in (0, 1, 2):   # cubic: C² across the seam
        dd = tuple(order * np.array(d))
        below = surf.derivative(*at(L * (1 - 1e-13)), *dd)   # last cell
        above = surf.derivative(*at(0.0), *dd)                # first cell
        np.testing.assert_allclose(below, above, atol=1e-8 * 10**order)
    eps = 1e-6
    exact_derivative = (exact(*at(eps)) - exact(*at(-eps))) / (2 * eps)
    assert np.abs(surf.derivative(*at(0.0), *d) - exact_derivative).max() < 1e-3


def test_cylinder_closes_up_around_its_axis():
    R, height = 0.8, 1.5
    surf = shapes.cylinder(radius=R, height=height, cells=(12, 3))
    assert surf.basis_u.kind == "periodic" and surf.basis_v.kind == "open"
    np.testing.assert_allclose(surf.domain, ((0, 2 * pi * R), (0, height)))
    assert surf.fit_error < 1e-3

    def exact(u, v):
        u, v = np.broadcast_arrays(u, v)
        return np.stack([R * np.cos(u / R), R * np.sin(u / R), v], -1)

    seam_check(surf, 0, exact)
    assert shapes.cylinder(knots="uniform", cells=(8, 3)).basis_v.kind == "uniform"
    assert shapes.cylinder(knots_v="uniform", cells=(8, 3)).basis_v.kind == "uniform"


def test_torus_closes_up_both_ways():
    R, r = 1.2, 0.5
    surf = shapes.torus(R=R, r=r, cells=(16, 10))
    assert surf.basis_u.kind == surf.basis_v.kind == "periodic"
    np.testing.assert_allclose(surf.domain, ((0, 2 * pi * R), (0, 2 * pi * r)))

    def exact(u, v):
        u, v = np.broadcast_arrays(u, v)
        ring = R + r * np.cos(v / r)
        return np.stack([ring * np.cos(u / R), ring * np.sin(u / R), r * np.sin(v / r)], -1)

    seam_check(surf, 0, exact)
    seam_check(surf, 1, exact)
    u, v = np.linspace(0, 2 * pi * R, 17), np.linspace(0, 2 * pi * r, 13)
    X = surf.evaluate_grid(u, v)
    tube = np.hypot(np.hypot(X[..., 0], X[..., 1]) - R, X[..., 2])
    assert np.abs(tube - r).max() <= surf.fit_error + 1e-12 and surf.fit_error < 1e-3


@pytest.mark.parametrize("name", ["plane", "saddle", "tile", "half_sphere", "cylinder",
                                  "torus"])
def test_each_shape_takes_cells_degree_knots_and_method(name):
    build = getattr(shapes, name)
    knots = "periodic" if name == "torus" else "uniform"
    surf = build(cells=(6, 5), degree=2, knots=knots, method="l2")
    assert surf.basis_u.degree == surf.basis_v.degree == 2
    assert (surf.basis_u.cells, surf.basis_v.cells) == (6, 5)
    assert surf.basis_v.kind == knots and surf.name == name
    assert surf.fit_error is not None and surf.fit_error < 0.05


# -- point grids ------------------------------------------------------------------------------
@pytest.mark.parametrize("method", ["interpolate", "l2"])
@pytest.mark.parametrize("knots", ["open", "uniform", "periodic"])
def test_point_grid_of_a_spline_is_fitted_exactly_by_least_squares(method, knots):
    bu, bv = BSplineBasis(3, 4, 1.0, knots), BSplineBasis(3, 3, 2.0, "open")
    P = np.random.default_rng(4).normal(size=(bu.size, bv.size, 3))
    source = Surface(P, bu, bv)
    u = np.linspace(0, 1, 15, endpoint=knots != "periodic")
    grid = source.evaluate_grid(u, np.linspace(0, 2, 9))
    fitted = shapes.from_points(grid, cells=(4, 3), degree=3, knots=(knots, "open"),
                                method=method, domain=((0, 1), (0, 2)))
    np.testing.assert_allclose(fitted.control_points, P, atol=1e-10)
    assert fitted.fit_error < 1e-12 and fitted.name == "points"


def test_point_grid_with_as_many_points_as_control_points_is_interpolated():
    u = np.linspace(0, 1, 7)
    grid = smooth_map(*np.meshgrid(u, u, indexing="ij"))
    fitted = shapes.from_points(grid, cells=4, degree=3)
    assert fitted.shape == (7, 7)
    # the samples sit evenly on the default domain, the grid's mean chord lengths
    (_, lu), (_, lv) = fitted.domain
    assert (lu, lv) == pytest.approx(shapes.chord_lengths(grid), rel=1e-15)
    su, sv = np.linspace(0, lu, 7), np.linspace(0, lv, 7)
    np.testing.assert_allclose(fitted.evaluate_grid(su, sv), grid, atol=1e-13)
    assert fitted.fit_error < 1e-13
    # more points than control points: least squares, close to the map but not through it
    v = np.linspace(0, 1, 41)
    dense = shapes.from_points(smooth_map(*np.meshgrid(v, v, indexing="ij")), cells=4)
    assert 1e-6 < dense.fit_error < 1e-2


def test_point_grid_of_a_panel_gets_its_lengths_so_the_parametric_energy_is_the_physical():
    """A 2 × 3 panel sampled evenly: the default domain is [0, 2] × [0, 3], where the
    parametric membrane (T = μ = 1, pinned edges) has the panel's lowest frequency
    ω₁₁ = π √(1/2² + 1/3²) and agrees with the energy measured on the surface."""
    u, v = np.linspace(0, 2, 7), np.linspace(0, 3, 9)
    grid = np.stack(np.broadcast_arrays(u[:, None], v[None, :], 0.0), -1)
    membrane = sd.Material(mass=1.0, damping=0.0, w10=1.0, w01=1.0, w20=0.0, w11=0.0, w02=0.0)
    exact = pi * np.sqrt(1 / 4 + 1 / 9)

    def lowest(surface, physics):
        return sd.Model(surface, membrane, boundary="pinned", physics=physics).frequencies(1)[0]

    panel = shapes.from_points(grid, cells=(4, 6))
    # the sum of 6 (8) equal chords of 1/3 (3/8), exact up to rounding
    assert np.ravel(panel.domain) == pytest.approx([0, 2, 0, 3], rel=1e-14)
    parametric, intrinsic = lowest(panel, "parametric"), lowest(panel, "intrinsic")
    # cubic elements on 4 × 6 cells: discretisation error 3.5e-6 of ω₁₁
    assert parametric == pytest.approx(exact, rel=1e-5)
    # isometric parametrisation: the two energies give the same matrices up to rounding
    assert parametric == pytest.approx(intrinsic, rel=1e-10)
    # the unit square squeezes the panel: its parametric energy is far from the physical one
    squeezed = shapes.from_points(grid, cells=(4, 6), domain=((0, 1), (0, 1)))
    assert abs(lowest(squeezed, "parametric") / exact - 1) > 1.0
    assert lowest(squeezed, "intrinsic") == pytest.approx(exact, rel=1e-5)


def test_chord_lengths_of_a_closed_grid_count_the_seam_once():
    t = np.linspace(0, 2 * pi, 25)
    z = np.linspace(0, 1, 6)
    closed = np.stack(np.broadcast_arrays(np.cos(t)[:, None], np.sin(t)[:, None], z), -1)
    # 24 chords of the unit circle, each 2 sin(π/24); the seam chord is the repeated row's
    polygon = 24 * 2 * np.sin(pi / 24)
    assert shapes.chord_lengths(closed, (True, False)) == pytest.approx((polygon, 1.0),
                                                                          rel=1e-14)
    assert shapes.chord_lengths(closed[:-1], (True, False)) == pytest.approx((polygon, 1.0),
                                                                               rel=1e-14)


def test_closed_point_grid_drops_the_repeated_seam():
    t = np.linspace(0, 2 * pi, 25)
    z = np.linspace(0, 1, 6)
    closed = np.stack(np.broadcast_arrays(np.cos(t)[:, None], np.sin(t)[:, None], z), -1)
    a = shapes.from_points(closed, cells=(12, 3), knots=("periodic", "open"),
                           domain=((0, 2 * pi), (0, 1)))
    b = shapes.from_points(closed[:-1], cells=(12, 3), knots=("periodic", "open"),
                           domain=((0, 2 * pi), (0, 1)))
    np.testing.assert_allclose(a.control_points, b.control_points, atol=1e-14)
    assert a.fit_error < 1e-3


@pytest.mark.parametrize("method", METHODS)
def test_from_function_samples_on_its_domain(method):
    surf = shapes.from_function(smooth_map, cells=(10, 12), domain=((2.0, 3.0), (-1.0, 0.0)),
                                method=method, name="bump")
    assert surf.domain == ((0.0, 1.0), (0.0, 1.0)) and surf.name == "bump"
    x = surf.evaluate(0.25, 0.5)
    np.testing.assert_allclose(x, smooth_map(np.array(2.25), np.array(-0.5)), atol=1e-4)


# -- bad input -------------------------------------------------------------------------------
@pytest.mark.parametrize("call, words", [
    (lambda: shapes.plane(method="cubic"), "fitting method must be one of"),
    (lambda: shapes.plane(knots="closed"), "knot layout in u must be one of"),
    (lambda: shapes.plane(knots=("open", "open", "open")), "one value or a pair"),
    (lambda: shapes.plane(cells=(0, 4)), "u direction: .*at least 1 cell"),
    (lambda: shapes.plane(cells=(4, 2.5)), "v direction: cells must be an integer"),
    (lambda: shapes.plane(degree=0), "degree must be an integer >= 1"),
    (lambda: shapes.plane(size=(-1, 1)), "plane size must be a positive"),
    (lambda: shapes.plane(size="big"), "plane size must be a positive"),
    (lambda: shapes.torus(cells=(8, 3)), r"v direction: .*cells >= degree \+ 1"),
    (lambda: shapes.torus(R=1.0, r=1.0), "smaller than R"),
    (lambda: shapes.tile(angle=7.0), r"angle must be in \(0, 2π\)"),
    (lambda: shapes.half_sphere(radius=0.0), "radius must be a positive"),
    (lambda: shapes.saddle(height=np.inf), "height must be finite"),
    (lambda: shapes.cylinder(knots=("open", "open")), "periodic around its axis"),
    (lambda: shapes.from_function(lambda u, v: np.stack([u, v, u * v]), cells=2),
     "stack the coordinates on the last axis"),
    (lambda: shapes.from_function(lambda u, v: np.stack([u, v, np.where(u > 0.5, np.nan, v)], -1)),
     r"not finite at \(u, v\)"),
    (lambda: shapes.from_function(lambda u, v: 1 / 0), "raised ZeroDivisionError"),
    (lambda: shapes.from_function(smooth_map, domain=((1, 0), (0, 1))), "u_min < u_max"),
    (lambda: shapes.from_function(smooth_map, domain=(0, 1)), r"domain must be \(\(u_min"),
    (lambda: shapes.from_points(np.zeros((5, 5)), cells=2), r"shape \(N_u, N_v, 3\)"),
    (lambda: shapes.from_points(np.full((9, 9, 3), np.nan), cells=2), "finite"),
    (lambda: shapes.from_points(np.zeros((5, 9, 3)), cells=4), "u direction: 5 sample"),
    (lambda: shapes.from_points(np.zeros((9, 9, 3)), method="quasi"),
     "must be one of \\('interpolate', 'l2'\\)"),
])
def test_bad_input_says_what_is_wrong(call, words):
    with pytest.raises(InputError, match=words):
        call()
