"""Assembly, boundary conditions, static and modal solves of the Model.

References are independent computations: brute-force 2-D Gauss quadrature of the energy
through ``Surface.evaluation_matrix`` (no Kronecker products), and the energy of a surface
evaluated pointwise.
"""

import numpy as np
import pytest
import scipy.sparse as sp
from hypothesis import given, settings
from hypothesis import strategies as st

import splinedeform as sd
from splinedeform.boundary import build_constraints
from splinedeform.errors import InputError, SingularSystemError
from splinedeform.quadrature import gauss_points

WEIGHT_NAMES = ("w10", "w01", "w20", "w11", "w02")
# (weight, du, dv, factor) of the energy density: w10|d_u|² + ... + 2 w11|d_uv|² + ...
ENERGY_TERMS = (("w10", 1, 0, 1.0), ("w01", 0, 1, 1.0), ("w20", 2, 0, 1.0),
                ("w11", 1, 1, 2.0), ("w02", 0, 2, 1.0))


def brute_force(surface, material, extra=3):
    """K and M by 2-D tensor Gauss quadrature with extra points, no Kronecker product."""
    xu, wu = gauss_points(surface.basis_u, surface.basis_u.degree + 1 + extra)
    xv, wv = gauss_points(surface.basis_v, surface.basis_v.degree + 1 + extra)
    U, V = np.meshgrid(xu, xv, indexing="ij")
    W = sp.diags((wu[:, None] * wv[None, :]).ravel())
    K = 0
    for name, du, dv, factor in ENERGY_TERMS:
        weight = getattr(material, name)
        if weight:
            E = surface.evaluation_matrix(U, V, du, dv)
            K = K + factor * weight * (E.T @ W @ E)
    E0 = surface.evaluation_matrix(U, V)
    return K.toarray(), (material.mass * (E0.T @ W @ E0)).toarray()


def random_material(rng, degree):
    w = rng.uniform(0.1, 2.0, 5)
    if degree < 2:
        w[[2, 4]] = 0.0
    return sd.Material(mass=rng.uniform(0.5, 2), **dict(zip(WEIGHT_NAMES, w)))


@pytest.mark.parametrize("knots", ["open", "uniform", "periodic"])
@pytest.mark.parametrize("degree", [1, 2, 3])
def test_assembly_matches_brute_force_quadrature(knots, degree):
    rng = np.random.default_rng(degree)
    cells = (degree + 2, degree + 3)
    if knots == "periodic":   # shapes.plane refuses periodic knots (not closed): fit the net
        bu, bv = (sd.BSplineBasis(degree, m, L, knots) for m, L in zip(cells, (1.3, 0.7)))
        P = sd.shapes.fit_control_points(lambda u, v: np.stack([u, v, 0 * u], -1), bu, bv)
        surf = sd.Surface(P, bu, bv)
    else:
        surf = sd.shapes.plane(size=(1.3, 0.7), cells=cells, degree=degree, knots=knots)
    for name in WEIGHT_NAMES:  # every weight alone, then all together
        if degree < 2 and name in ("w20", "w02"):
            continue
        mat = sd.Material(mass=1.7, **{name: 1.3})
        model = sd.Model(surf, mat)
        K_bf, M_bf = brute_force(surf, mat)
        assert np.allclose(model.K_full.toarray(), K_bf, rtol=0, atol=1e-11 * np.abs(K_bf).max())
        assert np.allclose(model.M_full.toarray(), M_bf, rtol=0, atol=1e-13)
    mat = random_material(rng, degree)
    model = sd.Model(surf, mat)
    K_bf, _ = brute_force(surf, mat)
    assert np.allclose(model.K_full.toarray(), K_bf, atol=1e-11 * np.abs(K_bf).max())
    assert abs(model.K_full - model.K_full.T).max() < 1e-12


@settings(max_examples=25, deadline=None)
@given(degree=st.integers(2, 4), mu=st.integers(2, 5), mv=st.integers(2, 5),
       knots=st.sampled_from(["open", "uniform"]), seed=st.integers(0, 2**16))
def test_quadratic_form_is_twice_the_energy(degree, mu, mv, knots, seed):
    """pᵀ K p = 2 E(p) with E from pointwise surface derivatives (property test)."""
    rng = np.random.default_rng(seed)
    surf = sd.shapes.plane(size=(1.0, 2.0), cells=(mu, mv), degree=degree, knots=knots)
    mat = random_material(rng, degree)
    model = sd.Model(surf, mat)
    d = rng.normal(size=surf.shape + (3,))
    xu, wu = gauss_points(surf.basis_u, degree + 2)
    xv, wv = gauss_points(surf.basis_v, degree + 2)
    U, V = np.meshgrid(xu, xv, indexing="ij")
    w = wu[:, None] * wv[None, :]
    energy = 0.0
    for name, du, dv, factor in ENERGY_TERMS:
        deriv = surf.derivative(U, V, du, dv, control_points=d)
        energy += 0.5 * factor * getattr(mat, name) * np.sum(w[..., None] * deriv**2)
    flat = d.reshape(-1, 3)
    assert np.isclose(np.sum(flat * (model.K_full @ flat)), 2 * energy, rtol=1e-11)
    kinetic = 0.5 * mat.mass * np.sum(w[..., None] * surf.derivative(U, V, control_points=d) ** 2)
    assert np.isclose(np.sum(flat * (model.M_full @ flat)), 2 * kinetic, rtol=1e-11)


@pytest.mark.parametrize("knots", ["open", "uniform"])
@pytest.mark.parametrize("degree", [2, 3, 4])
@pytest.mark.parametrize("preset", ["pinned", "clamped"])
def test_edge_presets_hold_on_the_surface(knots, degree, preset):
    """Every displacement d = T d_free vanishes (and its normal derivative) on the edges."""
    surf = sd.shapes.plane(cells=(5, 6), degree=degree, knots=knots)
    cons = build_constraints(surf.basis_u, surf.basis_v, preset)
    rng = np.random.default_rng(0)
    d = (cons.T @ rng.normal(size=(cons.n_free, 3))).reshape(surf.shape + (3,))
    s = np.linspace(0, 1, 17)
    zero = np.zeros_like(s)
    for u, v, du, dv in ((zero, s, 1, 0), (zero + 1, s, 1, 0), (s, zero, 0, 1), (s, zero + 1, 0, 1)):
        assert np.abs(surf.derivative(u, v, control_points=d)).max() < 1e-12
        slope = np.abs(surf.derivative(u, v, du, dv, control_points=d)).max()
        assert (slope < 1e-10) if preset == "clamped" else (slope > 1e-3)
    # the free coordinates are a basis of the constrained space: T has full column rank
    assert np.linalg.matrix_rank(cons.T.toarray()) == cons.n_free
    expected = {("pinned",): 1, ("clamped",): 2}[(preset,)]
    assert cons.n_free == (surf.shape[0] - 2 * expected) * (surf.shape[1] - 2 * expected)


def test_mixed_edges_and_kronecker_structure():
    surf = sd.shapes.plane(cells=(6, 5), knots="uniform")
    cons = build_constraints(surf.basis_u, surf.basis_v,
                             {"u0": "clamped", "u1": "pinned", "v0": "free", "v1": "clamped"})
    assert cons.T_u is not None and cons.T_v is not None
    assert abs(sp.kron(cons.T_u, cons.T_v) - cons.T).max() == 0
    assert cons.n_free == (9 - 3) * (8 - 2)


def _moved(d):
    """Points that move: displacement above 1e-9 of the largest (held points are zero rows
    of T; a free point under this load moves by at least 0.046 of the largest: measured)."""
    size = np.abs(d).max(axis=-1)
    return size > 1e-9 * size.max()


def test_fixed_mask_moves_only_the_free_region():
    surf = sd.shapes.plane(cells=(8, 8))
    fixed = np.ones(surf.shape, dtype=bool)
    fixed[3:7, 2:6] = False                     # a rectangle: Kronecker form survives
    model = sd.Model(surf, sd.Material(w10=1, w01=1), fixed=fixed)
    assert model.n_free == 16 and model.constraints.T_u is not None
    st = model.static(sd.Point(0.5, 0.45, (0, 0, -1)))
    moved = _moved(st.control_points() - surf.control_points)
    assert np.abs(moved.astype(int) - (~fixed).astype(int)).max() < 0.5   # 0/1 flags
    fixed[3, 2] = True                          # not a rectangle any more
    model = sd.Model(surf, sd.Material(w10=1, w01=1), fixed=fixed)
    assert model.n_free == 15 and model.constraints.T_u is None
    moved = _moved(model.static(sd.Point(0.5, 0.45, (0, 0, -1))).control_points()
                   - surf.control_points)
    assert np.abs(moved.astype(int) - (~fixed).astype(int)).max() < 0.5


def test_static_equals_energy_minimiser():
    """The static solution minimises ½dᵀKd - Fᵀd: perturbations raise the energy."""
    surf = sd.shapes.plane(cells=(6, 6))
    model = sd.Model(surf, sd.Material(w10=0.3, w01=0.3, w20=1, w11=1, w02=1), boundary="clamped")
    load = sd.Point(0.3, 0.7, (0.1, 0.2, -1.0)) + sd.Uniform((0, 0, -0.5))
    st = model.static(load)
    K = model.matrices()[2]
    F = model.load_vector(load)
    assert np.allclose(K @ st.d_free, F, atol=1e-12)
    e0 = st.energy().total
    rng = np.random.default_rng(1)
    for _ in range(5):
        d = st.d_free + 1e-3 * rng.normal(size=st.d_free.shape)
        assert 0.5 * np.sum(d * (K @ d)) - np.sum(F * d) > e0
    # by Clapeyron's theorem the strain energy is half the work at equilibrium
    assert np.isclose(st.energy().strain, 0.5 * st.energy().work, rtol=1e-12)


def test_point_load_reciprocity():
    """Maxwell–Betti: the deflection at B due to a load at A equals that at A due to B."""
    surf = sd.shapes.plane(cells=(7, 7), knots="uniform")
    model = sd.Model(surf, sd.Material(w10=1, w01=2, w20=0.1, w11=0.1, w02=0.1),
                     boundary={"u0": "clamped", "u1": "pinned", "v0": "pinned", "v1": "free"})
    a, b = (0.2, 0.3), (0.7, 0.8)
    wab = model.static(sd.Point(*a, (0, 0, 1))).displacement(*b)[2]
    wba = model.static(sd.Point(*b, (0, 0, 1))).displacement(*a)[2]
    assert np.isclose(wab, wba, rtol=1e-10)


def test_rest_none_pulls_the_surface_towards_zero_energy():
    """With rest='none' the energy is of the position itself: a membrane of a bumped
    surface with a pinned boundary relaxes to the harmonic extension of its boundary, a plane."""
    surf = sd.shapes.from_function(lambda u, v: np.stack([u, v, np.sin(np.pi * u) * np.sin(np.pi * v)], -1),
                                   cells=(8, 8))
    model = sd.Model(surf, sd.Material(w10=1, w01=1), boundary="pinned", rest="none")
    flat = model.static(None).surface()
    u = np.linspace(0, 1, 9)
    assert np.abs(flat.evaluate(u[:, None], u[None, :])[..., 2]).max() < 1e-12


def test_modes_are_m_orthonormal_and_sorted():
    surf = sd.shapes.plane(cells=(5, 6))
    model = sd.Model(surf, sd.Material(mass=2.0, w10=1, w01=1, w20=0.1, w11=0.1, w02=0.1),
                     boundary="pinned")
    lam, phi = model.eigen()
    M, _, K = model.matrices()
    assert np.allclose(phi.T @ (M @ phi), np.eye(lam.size), atol=1e-10)
    assert np.allclose(phi.T @ (K @ phi), np.diag(lam), atol=1e-8 * lam.max())
    assert np.all(np.diff(lam) >= 0)
    omega, shapes = model.modes(3)
    assert np.allclose(omega, np.sqrt(lam[:3])) and shapes.shape == (3,) + surf.shape
    assert np.allclose(model.frequencies(3), omega)


def test_unconstrained_surface_has_rigid_modes():
    surf = sd.shapes.plane(cells=(4, 4))
    model = sd.Model(surf, sd.Material(w20=1, w11=1, w02=1))
    lam, _ = model.eigen()
    # plate energy vanishes on the affine functions 1, u, v: three zero modes
    assert np.sum(lam < 1e-9 * lam.max()) == 3


def test_lumped_mass_is_diagonal_with_the_same_total():
    surf = sd.shapes.plane(cells=(6, 6))
    cons = sd.Model(surf, sd.Material(mass=3, w10=1, w01=1))
    lump = sd.Model(surf, sd.Material(mass=3, w10=1, w01=1), mass_matrix="lumped")
    assert np.isclose(lump.M_full.sum(), cons.M_full.sum()) and np.isclose(lump.M_full.sum(), 3.0)
    assert lump.M_full.nnz == lump.M_full.shape[0]


# ----------------------------------------------------------------------------- bad input
@pytest.mark.parametrize("kwargs, words", [
    ({"mass": -1.0, "w10": 1}, "mass"),
    ({"w10": float("nan")}, "finite"),
    ({"w20": float("inf")}, "finite"),
    ({"w10": -0.5}, ">= 0"),
    ({"damping": -1, "w10": 1}, "damping"),
    ({}, "all stiffness weights"),
    ({"w10": "soft"}, "number"),
])
def test_material_rejects_bad_values(kwargs, words):
    with pytest.raises(InputError, match=words):
        sd.Material(**kwargs)


def test_model_errors_say_what_is_wrong():
    surf = sd.shapes.plane(cells=(4, 4))
    mat = sd.Material(w10=1, w01=1)
    with pytest.raises(InputError, match=r"shape \(n_u, n_v\)"):
        sd.Model(surf, mat, fixed=np.zeros((3, 3), dtype=bool))
    with pytest.raises(InputError, match="edge"):
        sd.Model(surf, mat, boundary={"left": "clamped"})
    with pytest.raises(InputError, match="preset"):
        sd.Model(surf, mat, boundary="glued")
    with pytest.raises(InputError, match="degree >= 2"):
        sd.Model(sd.shapes.plane(cells=(4, 4), degree=1), sd.Material(w20=1))
    with pytest.raises(SingularSystemError, match="boundary"):
        sd.Model(surf, mat).static(sd.Uniform((0, 0, -1)))
    with pytest.raises(SingularSystemError, match="singular"):
        # tension only in u, edges in u free: every field constant in u is energy-free
        sd.Model(surf, sd.Material(w10=1), boundary={"v0": "pinned", "v1": "pinned"}).static(
            sd.Uniform((0, 0, -1)))
    model = sd.Model(surf, mat, boundary="clamped")
    with pytest.raises(InputError, match="outside the parameter domain"):
        model.static(sd.Point(1.5, 0.5, (0, 0, 1)))
    with pytest.raises(InputError, match="unknown method"):
        model.dynamic(None, 1.0, method="euler")
    with pytest.raises(InputError, match="t_end"):
        model.dynamic(None, -1.0)
    sol = model.dynamic(sd.Uniform((0, 0, 1)), 1.0)
    with pytest.raises(InputError, match=">= 0"):
        sol.control_points(-0.5)
    with pytest.raises(InputError, match="periodic"):
        sd.Model(sd.shapes.cylinder(cells=(8, 4)), mat, boundary="clamped")
    with pytest.raises(InputError, match="modes"):
        model.frequencies(10_000)


def test_pole_edge_moves_as_one_point():
    """A half sphere's pole row of control points coincides; with the 'pole' preset it stays
    a single point under any load, and the model is the one obtained by merging those
    coordinates by hand."""
    surf = sd.shapes.half_sphere(cells=(8, 4))
    mat = sd.Material(w10=1, w01=1, w20=0.05, w11=0.05, w02=0.05)
    model = sd.Model(surf, mat, boundary={"v0": "clamped", "v1": "pole"})
    torn = sd.Model(surf, mat, boundary={"v0": "clamped"})
    assert model.n_free == torn.n_free - surf.shape[0] + 1
    net = model.static(sd.Point(0.3, 1.2, (0.2, -0.1, -1.0))).control_points()
    assert np.ptp(net[:, -1, :], axis=0).max() < 1e-12        # the pole stays one point
    free_torn = torn.static(sd.Point(0.3, 1.2, (0.2, -0.1, -1.0))).control_points()
    assert np.ptp(free_torn[:, -1, :], axis=0).max() > 1e-4   # without it the pole tears
    with pytest.raises(InputError, match="open knots"):
        sd.Model(sd.shapes.plane(cells=(4, 4), knots="uniform"), mat, boundary={"u0": "pole"})
