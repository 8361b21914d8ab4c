"""Tensor-product surfaces: polynomial reproduction, derivatives, grids, meshes, bad input."""

from itertools import combinations

import numpy as np
import pytest
from scipy.interpolate import BSpline

from splinedeform.basis import BSplineBasis
from splinedeform.errors import InputError
from splinedeform.surface import Surface, grid_faces


def blossom_coefficients(basis, power):
    """Coefficients of ``x^power`` (``power <= n``) in the basis, from the polar form:
    ``c_j = e_power(t_{j+1}, ..., t_{j+n}) / C(n, power)`` (elementary symmetric mean)."""
    t, n = basis.knots, basis.degree
    out = []
    for j in range(basis.size):
        window = t[j + 1: j + n + 1]
        subsets = list(combinations(window, power))
        out.append(np.mean([np.prod(s) for s in subsets]))
    return np.array(out)


def net_of(fu, fv, combine):
    """Control net ``P[k, l] = combine(fu[k], fv[l])`` with ``combine -> (..., 3)``."""
    return combine(fu[:, None], fv[None, :])


def random_parameters(surface, count=50, seed=0):
    rng = np.random.default_rng(seed)
    (a, b), (c, d) = surface.domain
    return rng.uniform(a, b, count), rng.uniform(c, d, count)


@pytest.mark.parametrize("kind", ["open", "uniform"])
@pytest.mark.parametrize("degree", [1, 2, 3, 4])
def test_bilinear_net_reproduces_the_bilinear_map_and_its_derivatives(kind, degree):
    """x = A + B u + C v + D u v from p_kl = A + B ξ_k + C η_l + D ξ_k η_l (knot averages)."""
    bu, bv = BSplineBasis(degree, 4, 2.0, kind), BSplineBasis(degree, 3, 1.5, kind)
    A, B, C, D = np.random.default_rng(degree).normal(size=(4, 3))
    xi, eta = blossom_coefficients(bu, 1), blossom_coefficients(bv, 1)
    if kind == "uniform" and degree > 1:   # outer knot averages lie outside [0, L], as expected
        assert xi[0] < 0 and xi[-1] > 2.0
    P = net_of(xi, eta, lambda x, y: A + B * x[..., None] + C * y[..., None]
               + D * (x * y)[..., None])
    surf = Surface(P, bu, bv)
    u, v = random_parameters(surf)
    U, V = u[:, None], v[:, None]
    np.testing.assert_allclose(surf.evaluate(u, v), A + B * U + C * V + D * U * V, atol=1e-13)
    np.testing.assert_allclose(surf.derivative(u, v, 1, 0), B + D * V + 0 * U, atol=1e-12)
    np.testing.assert_allclose(surf.derivative(u, v, 0, 1), C + D * U + 0 * V, atol=1e-12)
    np.testing.assert_allclose(surf.derivative(u, v, 1, 1), np.broadcast_to(D, (50, 3)),
                               atol=1e-11)
    np.testing.assert_allclose(surf.derivative(u, v, 2, 0), 0.0, atol=1e-10)


@pytest.mark.parametrize("kind", ["open", "uniform"])
@pytest.mark.parametrize("degree", [2, 3, 5])
def test_second_derivatives_of_a_quadratic_map(kind, degree):
    """x = (u², v², u v) from its polar form: x_uu = (2,0,0), x_vv = (0,2,0), x_uv = (0,0,1)."""
    bu, bv = BSplineBasis(degree, 5, 1.0, kind), BSplineBasis(degree, 4, 2.0, kind)
    u1, u2 = blossom_coefficients(bu, 1), blossom_coefficients(bu, 2)
    v1, v2 = blossom_coefficients(bv, 1), blossom_coefficients(bv, 2)
    P = np.stack(np.broadcast_arrays(u2[:, None], v2[None, :], u1[:, None] * v1[None, :]), -1)
    surf = Surface(P, bu, bv)
    u, v = random_parameters(surf, seed=3)
    exact = np.stack([u**2, v**2, u * v], -1)
    np.testing.assert_allclose(surf.evaluate(u, v), exact, atol=1e-12)
    np.testing.assert_allclose(surf.derivative(u, v, 1, 0),
                               np.stack([2 * u, 0 * u, v], -1), atol=1e-11)
    np.testing.assert_allclose(surf.derivative(u, v, 2, 0),
                               np.broadcast_to([2.0, 0, 0], (50, 3)), atol=1e-9)
    np.testing.assert_allclose(surf.derivative(u, v, 0, 2),
                               np.broadcast_to([0, 2.0, 0], (50, 3)), atol=1e-9)
    np.testing.assert_allclose(surf.derivative(u, v, 1, 1),
                               np.broadcast_to([0, 0, 1.0], (50, 3)), atol=1e-9)


@pytest.fixture
def random_surface():
    rng = np.random.default_rng(11)
    bu, bv = BSplineBasis(3, 5, 2.0, "open"), BSplineBasis(2, 6, 1.0, "periodic")
    return Surface(rng.normal(size=(bu.size, bv.size, 3)), bu, bv, name="random")


def test_evaluation_equals_the_double_sum_with_scipy_bases(random_surface):
    """x(u,v) = Σ_k Σ_l p_kl b_k(u) b_l(v), with b_k(u) from scipy for the open direction."""
    s = random_surface
    u, v = random_parameters(s, 30, seed=5)
    Bu = BSpline(s.basis_u.knots, np.eye(s.basis_u.size), 3)(u)
    Bv = s.basis_v(v)
    expected = np.einsum("ik,il,klc->ic", Bu, Bv, s.control_points)
    np.testing.assert_allclose(s.evaluate(u, v), expected, atol=1e-12)


def test_grid_pointwise_and_matrix_evaluations_agree(random_surface):
    s = random_surface
    u, v = np.linspace(0, 2, 9), np.linspace(0, 1, 7)
    U, V = np.meshgrid(u, v, indexing="ij")
    for du, dv in [(0, 0), (1, 0), (0, 1), (1, 1), (2, 0), (0, 2)]:
        grid = s.evaluate_grid(u, v, du, dv)
        assert grid.shape == (9, 7, 3)
        np.testing.assert_allclose(grid, s.derivative(U, V, du, dv), atol=1e-11)
        E = s.evaluation_matrix(U, V, du, dv)
        assert E.shape == (63, s.shape[0] * s.shape[1])
        np.testing.assert_allclose(E @ s.control_points.reshape(-1, 3),
                                   s.derivative(U, V, du, dv).reshape(-1, 3), atol=1e-11)
    # evaluate and derivative of order (0, 0) may take different paths (the per-span Bernstein
    # patches or the basis matrices): the same sums in another order, so equal to a few
    # roundings of the surface's size (1e-14 of it)
    size = float(np.ptp(s.control_points.reshape(-1, 3), axis=0).max())
    np.testing.assert_allclose(s.evaluate(U, V), s.derivative(U, V), rtol=0, atol=1e-14 * size)


def test_other_control_points_and_broadcasting(random_surface):
    s = random_surface
    Q = np.random.default_rng(2).normal(size=s.shape + (3,))
    u, v = np.linspace(0, 2, 5), 0.3
    np.testing.assert_allclose(s.derivative(u, v, control_points=Q),
                               s.with_control_points(Q).evaluate(u, v), atol=1e-14)
    np.testing.assert_allclose(s.derivative(u, v, control_points=Q + s.control_points),
                               s.evaluate(u, v) + s.with_control_points(Q).evaluate(u, v),
                               atol=1e-12)
    assert s.evaluate(u[:, None], np.zeros(4)).shape == (5, 4, 3)
    # scalar fields on the net evaluate too (one value per control point)
    w = Q[..., 0]
    np.testing.assert_allclose(s.evaluate_grid(u, [0.3], control_points=w[..., None])[:, 0, 0],
                               s.derivative(u, v, control_points=Q)[:, 0], atol=1e-14)


def test_periodic_direction_closes_up_smoothly(random_surface):
    s = random_surface   # periodic quadratic in v: x and x_v continuous across v = 1 ≡ 0
    u = np.linspace(0, 2, 7)
    for dv in (0, 1):
        np.testing.assert_allclose(s.derivative(u, 1.0 - 1e-12, 0, dv),
                                   s.derivative(u, 0.0, 0, dv), atol=1e-9)


@pytest.mark.parametrize("kind", ["open", "uniform"])
def test_plane_normals_mesh_and_area(kind):
    Lu, Lv = 2.0, 0.75
    bu, bv = BSplineBasis(3, 4, Lu, kind), BSplineBasis(2, 3, Lv, kind)
    xi, eta = blossom_coefficients(bu, 1), blossom_coefficients(bv, 1)
    P = np.stack(np.broadcast_arrays(xi[:, None], eta[None, :], 0.0), -1)
    surf = Surface(P, bu, bv)
    u, v = random_parameters(surf, 20)
    np.testing.assert_allclose(surf.normal(u, v), np.broadcast_to([0, 0, 1.0], (20, 3)),
                               atol=1e-13)
    flipped = surf.with_control_points(P[:, :, [1, 0, 2]])   # swap x, y: normal -z
    np.testing.assert_allclose(flipped.normal(u, v), np.broadcast_to([0, 0, -1.0], (20, 3)),
                               atol=1e-13)
    vertices, faces = surf.tessellate((9, 5))
    assert vertices.shape == (45, 3) and faces.shape == (2 * 8 * 4, 3)
    assert faces.min() == 0 and faces.max() == 44
    assert np.all([len(set(f)) == 3 for f in faces])
    tri = vertices[faces]
    cross = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    assert 0.5 * np.linalg.norm(cross, axis=1).sum() == pytest.approx(Lu * Lv, rel=1e-13)
    assert np.all(cross[:, 2] > 0)   # counter-clockwise: face normals follow x_u × x_v
    # each interior edge is shared by exactly two triangles (a valid manifold grid)
    edges = np.sort(np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]), 1)
    _, counts = np.unique(edges, axis=0, return_counts=True)
    boundary_edges = 2 * (8 + 4)
    assert (counts == 1).sum() == boundary_edges and set(counts) <= {1, 2}


def test_grid_faces_of_two_by_two_vertices():
    faces = grid_faces(2, 2)
    assert faces.dtype.kind == "i"                # vertex indices: integers, compared exactly
    assert faces.tolist() == [[0, 2, 3], [0, 3, 1]]


def test_layout_and_copies(random_surface):
    s = random_surface
    assert s.shape == (8, 6)
    assert s.domain == ((0.0, 2.0), (0.0, 1.0))
    with pytest.raises(ValueError):
        s.control_points[0, 0, 0] = 1.0     # the net is read-only
    fitted = Surface(s.control_points, s.basis_u, s.basis_v, fit_error=1e-3, name="fit")
    moved = fitted.with_control_points(s.control_points + 1.0)
    assert moved.fit_error is None and moved.name == "fit"
    assert fitted.with_control_points(s.control_points, name="b").name == "b"


def test_degenerate_normal_is_refused():
    b = BSplineBasis(1, 1, 1.0, "open")
    P = np.zeros((2, 2, 3))
    P[1, :, 0] = 1.0                         # x_v = 0 everywhere: a segment, not a surface
    with pytest.raises(InputError, match="degenerate"):
        Surface(P, b, b).normal(0.5, 0.5)


def test_bad_input_says_what_is_wrong():
    b = BSplineBasis(2, 3, 1.0, "open")
    with pytest.raises(InputError, match=r"shape \(5, 5, 3\)"):
        Surface(np.zeros((5, 4, 3)), b, b)
    with pytest.raises(InputError, match=r"shape \(5, 5, 3\)"):
        Surface(np.zeros((5, 5)), b, b)
    P = np.zeros((5, 5, 3))
    P[2, 3, 1] = np.nan
    with pytest.raises(InputError, match=r"finite; control point \(2, 3\)"):
        Surface(P, b, b)
    s = Surface(np.zeros((5, 5, 3)), b, b)
    with pytest.raises(InputError, match="outside the domain"):
        s.evaluate(1.5, 0.5)
    with pytest.raises(InputError, match="finite"):
        s.evaluate_grid([np.inf], [0.5])
    with pytest.raises(InputError, match="resolution must be >= 2"):
        s.tessellate(1)


def test_reprs_of_surfaces_are_one_short_line_naming_size_degree_knots_domain():
    from splinedeform import shapes
    from splinedeform.cad import NurbsPatch
    from splinedeform.knots import KnotVectorBasis, RationalBasis

    big = shapes.plane(size=(2.0, 3.0), cells=(61, 61))
    text = repr(big)
    assert "\n" not in text and len(text) < 200                  # not the 64 × 64 net
    for part in ("'plane'", "64×64 control points", "degree=(3, 3)", "'open' 61 cells",
                 "domain=[0, 2] × [0, 3]", "fit_error="):
        assert part in text, (part, text)
    arc = RationalBasis(KnotVectorBasis(2, [0, 0, 0, 1, 1, 1]), [1, 0.5 ** 0.5, 1])
    line = KnotVectorBasis(1, [0, 0, 0.5, 1, 1])
    rational = Surface(np.zeros((3, 3, 3)), arc, line)
    assert repr(rational) == ("Surface('surface', 3×3 control points, degree=(2, 1), "
                              "knots=(rational knot vector of 6, knot vector of 5), "
                              "domain=[0, 1] × [0, 1])")
    patch = NurbsPatch((2, 2), np.array([0, 0, 0, 2, 2, 2.0]), np.linspace(-1, 1, 40),
                       np.zeros((3, 37, 3)), np.ones((3, 37)))
    text = repr(patch)
    assert "\n" not in text and len(text) < 200
    assert text == ("NurbsPatch(3×37 control points, degree=(2, 2), knots=(knot vector of 6, "
                    "knot vector of 40), domain=[0, 2] × [-0.897436, 0.897436], equal weights)")
