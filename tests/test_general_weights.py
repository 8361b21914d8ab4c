"""NURBS surfaces whose weights are not a product ``a_k b_l`` (``Surface.net_weights``)."""

import numpy as np
import pytest

import splinedeform as sd
from splinedeform.cad import (NurbsPatch, patch_from_surface, read_3dm, surface_from_patch,
                              write_3dm)
from splinedeform.errors import InputError
from splinedeform.knots import KnotVectorBasis, RationalBasis

KNOTS_U = [0, 0, 0, 0, 0.2, 0.45, 0.7, 1, 1, 1, 1]          # degree 3, 7 functions
KNOTS_V = [0, 0, 0, 0.3, 0.5, 0.8, 1, 1, 1]                 # degree 2, 6 functions


def _bases():
    return KnotVectorBasis(3, KNOTS_U), KnotVectorBasis(2, KNOTS_V)


def _curved_net(bu, bv):
    X, Y = np.meshgrid(bu.greville(), bv.greville(), indexing="ij")
    return np.stack([X, Y, 0.2 * np.sin(2 * X + Y)], axis=-1)


def _general_weights(shape, seed=3):
    """Weights in [0.6, 1.6] of rank > 1 (a random field, not a product)."""
    w = np.random.default_rng(seed).uniform(0.6, 1.6, shape)
    assert sd.rational.product_factors(w) is None
    return w


def _relative(A, B):
    A, B = (np.asarray(X.toarray() if hasattr(X, "toarray") else X) for X in (A, B))
    return np.abs(A - B).max() / np.abs(A).max()


@pytest.mark.parametrize("physics", ["parametric", "intrinsic"])
def test_product_weights_given_per_point_match_the_product_path(physics):
    """The same rational space two ways: per-direction ``RationalBasis`` (Kronecker Gram
    matrices, ``2n + 10`` Gauss points per span) and the same weights ``a bᵀ`` given per
    control point (element by element, the quotient rule on a 2-D grid). Different
    quadrature orders of one rational integrand, both far beyond its polynomial part:
    K, M, the static answer and 6 frequencies agree to 1e-12 relative."""
    bu, bv = _bases()
    rng = np.random.default_rng(1)
    a, b = rng.uniform(0.7, 1.4, bu.size), rng.uniform(0.7, 1.4, bv.size)
    P = _curved_net(bu, bv)
    product = sd.Surface(P, RationalBasis(bu, a), RationalBasis(bv, b))
    general = sd.Surface(P, bu, bv, net_weights=np.outer(a, b))
    material = (sd.Material(w10=1, w01=1, w20=0.05, w11=0.05, w02=0.05) if physics ==
                "intrinsic" else sd.Material(w10=1, w01=2, w20=0.05, w11=0.02, w02=0.03))
    one, two = (sd.Model(s, material, boundary="clamped", physics=physics)
                for s in (product, general))
    M1, _, K1 = one.matrices()
    M2, _, K2 = two.matrices()
    assert _relative(K1, K2) <= 1e-12 and _relative(M1, M2) <= 1e-12
    # a point load is R_kl(u, v) f in both (no quadrature): the static answers agree
    point = sd.Point(0.37, 0.61, [0.3, -0.2, 1.0])
    d1, d2 = (model.static(point).d_free for model in (one, two))
    assert _relative(d1, d2) <= 1e-12
    # a pressure is integrated with n + 1 + ceil(n/2) points per span on the product path
    # (exact for polynomial bases only) and n + 10 on the general one: measured 1e-6 apart
    d1, d2 = (model.static(sd.Pressure(1.0)).d_free for model in (one, two))
    assert _relative(d1, d2) <= 5e-6
    assert _relative(one.frequencies(6), two.frequencies(6)) <= 1e-12


def test_evaluation_matches_geomdl():
    """Points, first and second derivatives, normals and the evaluation matrix of a
    non-product rational patch against geomdl's NURBS surface (an independent
    implementation, Piegl & Tiller A4.4): to 1e-12 of the net's size."""
    NURBS = pytest.importorskip("geomdl.NURBS")
    bu, bv = _bases()
    P, w = _curved_net(bu, bv), _general_weights((bu.size, bv.size))
    surface = sd.Surface(P, bu, bv, net_weights=w)
    ref = NURBS.Surface()
    ref.degree_u, ref.degree_v = 3, 2
    ref.ctrlpts_size_u, ref.ctrlpts_size_v = bu.size, bv.size
    ref.ctrlpts = P.reshape(-1, 3).tolist()
    ref.weights = w.ravel().tolist()
    ref.knotvector_u, ref.knotvector_v = list(map(float, KNOTS_U)), list(map(float, KNOTS_V))
    rng = np.random.default_rng(5)
    u, v = rng.uniform(0, 1, 40), rng.uniform(0, 1, 40)
    derivatives = np.array([ref.derivatives(float(s), float(t), order=2)
                            for s, t in zip(u, v)])                  # (points, k, l, 3)
    scale = np.abs(derivatives).max(axis=0)
    flat = P.reshape(-1, 3)
    for du, dv in ((0, 0), (1, 0), (0, 1), (2, 0), (1, 1), (0, 2)):
        want = derivatives[:, du, dv]
        tol = 1e-12 * scale[du, dv].max()
        assert np.abs(surface.derivative(u, v, du, dv) - want).max() <= tol
        assert np.abs(surface.evaluation_matrix(u, v, du, dv) @ flat - want).max() <= tol
        grid = surface.evaluate_grid(u, v, du, dv)[np.arange(u.size), np.arange(v.size)]
        assert np.abs(grid - want).max() <= tol
    assert np.abs(surface.evaluate(float(u[0]), float(v[0])) - derivatives[0, 0, 0]).max() \
        <= 1e-12 * scale[0, 0].max()
    cross = np.cross(derivatives[:, 1, 0], derivatives[:, 0, 1])
    normals = cross / np.linalg.norm(cross, axis=-1, keepdims=True)
    assert np.abs(surface.normal(u, v) - normals).max() <= 1e-12   # unit vectors


def _membrane_integral(series_terms=199):
    """``∫∫ d`` of ``-T Δd = q`` on the unit square, ``d = 0`` on its edges (q = T = 1):
    ``Σ_{m,n odd} 64 / (π⁶ m² n² (m² + n²))`` (Fourier sine series); the tail beyond
    ``m, n <= 199`` is 1e-7 of the sum (measured against 1999 terms)."""
    m = np.arange(1, series_terms + 1, 2.0)
    M, N = np.meshgrid(m, m)
    return float(np.sum(64.0 / (np.pi ** 6 * M ** 2 * N ** 2 * (M ** 2 + N ** 2))))


def test_flat_membrane_does_not_see_the_parametrisation():
    """A flat unit square, once with unit weights and once with general weights (which
    move only the parametrisation: the control points stay a monotone planar grid, so the
    surface is the same square). Under the intrinsic physics (tension only) and a pressure
    per unit area, pinned edges, the load's work ``∫ q d dA`` must be the same up to
    discretisation error, and match the Fourier series of the membrane. Measured at
    degree 3: both -1.1e-5 of the series at 6 × 6 cells, -5.9e-7 (unit weights) and
    -6.7e-7 (reweighted) at 12 × 12 (the rate h⁴ of the energy); the tolerance 2e-6 is
    three times the discretisation error at 12 × 12."""
    basis = sd.BSplineBasis(3, 12, 1.0, "open")
    g = basis.greville()
    X, Y = np.meshgrid(g, g, indexing="ij")
    P = np.stack([X, Y, np.zeros_like(X)], axis=-1)
    w = 1.0 + 0.4 * np.sin(np.pi * X) * np.sin(np.pi * Y) * (X + 0.5) * np.cos(Y)
    assert sd.rational.product_factors(w) is None
    material = sd.Material(w10=1.0, w01=1.0)
    closed_form = _membrane_integral()
    works = []
    for surface in (sd.Surface(P, basis, basis), sd.Surface(P, basis, basis, net_weights=w)):
        model = sd.Model(surface, material, boundary="pinned", physics="intrinsic")
        solution = model.static(sd.Pressure(1.0))
        works.append(float(np.sum(solution.force_free * solution.d_free)))
    assert abs(works[0] - closed_form) <= 2e-6 * closed_form
    assert abs(works[1] - closed_form) <= 2e-6 * closed_form
    assert abs(works[1] - works[0]) <= 2e-6 * closed_form


def _rational_patch():
    bu, bv = _bases()
    P, w = _curved_net(bu, bv), _general_weights((bu.size, bv.size))
    return NurbsPatch((3, 2), np.asarray(KNOTS_U, float), np.asarray(KNOTS_V, float), P, w)


def test_cad_patch_with_general_weights_is_accepted_and_round_trips(tmp_path):
    """``surface_from_patch`` keeps general weights per control point and evaluates the
    patch's own formula; a .3dm written from it and read back by rhino3dm has the same
    weights (stored as float64: equal to the last bits, 1e-15) and the same points at
    rhino3dm's own evaluation (1e-12 of the size, openNURBS's evaluator)."""
    r3 = pytest.importorskip("rhino3dm")
    patch = _rational_patch()
    surface = surface_from_patch(patch)
    assert surface.net_weights is not None
    u, v = np.linspace(0, 1, 9), np.linspace(0, 1, 7)
    size = np.abs(patch.points).max()
    assert np.abs(surface.evaluate_grid(u, v) - patch.evaluate(u, v)).max() <= 1e-13 * size
    written = write_3dm(tmp_path / "general.3dm", [patch_from_surface(surface)])
    model = r3.File3dm.Read(str(written))
    srf = model.Objects[0].Geometry
    stored = np.array([[srf.Points[i, j].W for j in range(srf.Points.CountV)]
                       for i in range(srf.Points.CountU)])
    assert np.abs(stored - patch.weights).max() <= 1e-15 * patch.weights.max()
    points = np.array([[(lambda p: [p.X, p.Y, p.Z])(srf.PointAt(float(s), float(t)))
                        for t in v] for s in u])
    assert np.abs(points - surface.evaluate_grid(u, v)).max() <= 1e-12 * size
    back = surface_from_patch(read_3dm(written))
    assert np.abs(back.net_weights - surface.net_weights).max() <= 1e-15 * patch.weights.max()


def test_refinement_keeps_a_general_weight_surface():
    """Knot insertion and degree elevation in homogeneous coordinates: the geometry is
    unchanged to 1e-12 of its size (round-off of the refinement solves)."""
    surface = surface_from_patch(_rational_patch())
    fine = sd.refine.refine_surface(surface, elevate=(1, 0), insert=(1, 2))
    assert fine.net_weights is not None and fine.shape != surface.shape
    u, v = np.linspace(0, 1, 11), np.linspace(0, 1, 13)
    assert np.abs(fine.evaluate_grid(u, v) - surface.evaluate_grid(u, v)).max() <= 1e-12


def test_bad_general_weights_are_refused():
    bu, bv = _bases()
    P = _curved_net(bu, bv)
    with pytest.raises(InputError, match=r"net_weights must have shape \(7, 6\)"):
        sd.Surface(P, bu, bv, net_weights=np.ones((6, 6)))
    w = np.ones((7, 6))
    w[2, 3] = -1.0
    with pytest.raises(InputError, match=r"net_weights\[2, 3\] is -1"):
        sd.Surface(P, bu, bv, net_weights=w)
    with pytest.raises(InputError, match="direction u is not"):
        sd.Surface(np.zeros((7, 6, 3)), sd.BSplineBasis(3, 4, 1.0, "uniform"), bv,
                   net_weights=np.ones((7, 6)))
    with pytest.raises(InputError, match="not both"):
        sd.Surface(P, RationalBasis(bu, np.ones(7)), bv, net_weights=np.ones((7, 6)))


def _bump_weights(surface, amplitude=0.4):
    """``1 + a sin(π s) sin(π t) (s + 1/2) cos t`` at the Greville points ``(s, t)`` of the
    patch's own parameters scaled to [0, 1]: 1 on its edges, not a product inside."""
    gu = surface.basis_u.greville() / surface.basis_u.length
    gv = surface.basis_v.greville() / surface.basis_v.length
    S, T = np.meshgrid(gu, gv, indexing="ij")
    return 1.0 + amplitude * np.sin(np.pi * S) * np.sin(np.pi * T) * (S + 0.5) * np.cos(T)


def test_a_body_of_reweighted_halves_is_the_same_membrane():
    """The unit square as two patches (one reversed in u and v, so its normal still points
    up), each with general weights that are 1 on its edges (so the halves still conform
    along the shared edge): the intrinsic membrane under pressure gives the load's work of
    the Fourier series within the discretisation error at this mesh (6 × 12 cells of
    degree 3 per half; measured -5.9e-7 with unit weights, -8.1e-7 reweighted; tolerance
    2e-6 as for the single patch)."""
    from body_patches import flat_patch

    halves = [flat_patch((0, 0.5), (0, 1), (6, 12)),
              flat_patch((0.5, 1), (0, 1), (6, 12), reverse_u=True, reverse_v=True)]
    halves = [sd.Surface(h.control_points, h.basis_u, h.basis_v, net_weights=_bump_weights(h))
              for h in halves]
    body = sd.BodyModel(sd.Body(halves), sd.Material(w10=1.0, w01=1.0), boundary="pinned")
    solution = body.static(sd.Pressure(1.0))
    work = float(np.sum(solution.force_free * solution.d_free))
    closed_form = _membrane_integral()
    assert abs(work - closed_form) <= 2e-6 * closed_form


def test_meshes_of_frames_and_a_step_round_trip_keep_general_weights(tmp_path):
    """Meshes of many frames (one pair of 1-D matrices for all) equal each frame's own
    evaluation (two evaluations of one quotient: 1e-13 of the size); a STEP file written
    and read back by OpenCASCADE keeps the weights and the surface (OpenCASCADE writes
    reals with 12 significant digits: 5e-13 of each number, so 1e-12 of the largest
    weight, and 3e-12 of the size for a point, a weighted mean of such numbers)."""
    from splinedeform.export.frames import tessellate_frames

    surface = surface_from_patch(_rational_patch())
    P = surface.control_points
    nets = np.stack([P, P + 0.1 * np.sin(P[..., ::-1])])
    vertices, _ = tessellate_frames(surface, nets, 9)
    size = np.abs(nets).max()
    for frame in range(2):
        own = surface.with_control_points(nets[frame]).tessellate(9)[0]
        assert np.abs(vertices[frame] - own).max() <= 1e-13 * size
    pytest.importorskip("OCP")
    from splinedeform.cad_step import read_step, write_step

    written = write_step(tmp_path / "general.step", [patch_from_surface(surface)])
    back = read_step(written)
    w = surface.net_weights
    assert np.abs(np.asarray(back.weights) - w).max() <= 1e-12 * w.max()
    u, v = np.linspace(0, 1, 9), np.linspace(0, 1, 7)
    again = surface_from_patch(back)
    assert np.abs(again.evaluate_grid(u, v) - surface.evaluate_grid(u, v)).max() \
        <= 3e-12 * np.abs(P).max()


def test_a_cad_patch_with_general_weights_and_unclamped_knots_is_refused():
    patch = _rational_patch()
    knots = np.asarray(KNOTS_U, float)
    knots[:3] = [-0.3, -0.2, -0.1]                          # unclamped start in u
    odd = NurbsPatch(patch.degrees, knots, patch.knots_v, patch.points, patch.weights)
    with pytest.raises(InputError, match="blade.3dm face 2: its weights are not a product "
                                         "w_ij = a_i b_j and its knot vector in u is not"):
        surface_from_patch(odd, source="blade.3dm face 2")


def test_coupling_traces_of_an_edge_use_the_rational_basis():
    """A side's traces (values and outward conormal slopes along an edge, used by the
    coupling of interfaces and C0 lines) on general weights: applied to a smooth field
    ``d = R · f`` they equal the surface's own evaluation of that field and the conormal
    slope from its derivatives (two evaluations of one quotient: 1e-12 of the field)."""
    from splinedeform.physics.coupling_traces import Side

    surface = surface_from_patch(_rational_patch())
    field = np.sin(3 * surface.control_points)                      # another net, (7, 6, 3)
    s = np.linspace(0.05, 0.95, 9)
    for edge, (u, v) in (("u0", (0 * s, s)), ("v1", (s, 0 * s + 1.0))):
        trace = Side.of_edge(surface, edge).traces(s)
        flat = field.reshape(-1, 3)
        want = surface.derivative(u, v, control_points=field)
        scale = np.abs(want).max()
        assert np.abs(trace.values @ flat - want).max() <= 1e-12 * scale
        assert np.abs(trace.points - surface.evaluate(u, v)).max() <= 1e-12
        x_u, x_v = surface.derivative(u, v, 1, 0), surface.derivative(u, v, 0, 1)
        d_u = surface.derivative(u, v, 1, 0, control_points=field)
        d_v = surface.derivative(u, v, 0, 1, control_points=field)
        x_f, x_r, d_f, d_r = (x_u, x_v, d_u, d_v) if edge[0] == "u" else (x_v, x_u, d_v, d_u)
        c = np.einsum("qi,qi->q", x_f, x_r) / np.einsum("qi,qi->q", x_r, x_r)
        outward = -1.0 if edge[1] == "0" else 1.0
        slope = outward * (d_f - c[:, None] * d_r) / np.linalg.norm(
            x_f - c[:, None] * x_r, axis=1)[:, None]
        assert np.abs(trace.slopes @ flat - slope).max() <= 1e-12 * np.abs(slope).max()
