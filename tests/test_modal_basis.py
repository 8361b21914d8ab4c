"""Eigen-solution strategies: separable Kronecker modes, sparse Lanczos, mode acceleration.

References are independent computations: the dense generalised ``eigh`` of the assembled
reduced matrices (the reference path), the sparse direct static solve, and the closed-form
bound of the mode-acceleration error for a step load.
"""

import numpy as np
import pytest
import scipy.sparse as sp

import splinedeform as sd
from splinedeform.errors import InputError
from splinedeform import spectrum
from splinedeform.solvers import modal_basis as mb

MATERIAL = sd.Material(mass=1.7, damping=0.3, rayleigh=1e-3, w10=2.0, w01=1.0, w20=0.5,
                       w02=0.3)
LOAD = (sd.Point(0.3, 0.6, (0.2, 0.0, -1.0), profile=sd.Step(0.1, 0.5))
        + sd.Uniform((0.0, 0.1, 0.0), profile=sd.Harmonic(7.0, 0.3)))
TIMES = np.linspace(0.0, 1.0, 7)


def rectangle_mask(shape):
    mask = np.ones(shape, bool)
    mask[2:7, 3:9] = False
    return mask


CASES = {
    "open clamped": {"knots": "open", "boundary": "clamped"},
    "uniform mixed edges": {"knots": "uniform", "boundary": {"u0": "clamped", "u1": "pinned",
                                                           "v0": "free", "v1": "clamped"}},
    "uniform pinned": {"knots": "uniform", "boundary": "pinned"},
    "open free region": {"knots": "open", "boundary": "free", "region": True},
}


def model_for(case, material=MATERIAL, cells=(7, 9)):
    spec = CASES[case]
    surf = sd.shapes.plane(size=(1.0, 1.3), cells=cells, knots=spec["knots"])
    fixed = rectangle_mask(surf.shape) if spec.get("region") else None
    return sd.Model(surf, material, boundary=spec["boundary"], fixed=fixed)


@pytest.mark.parametrize("case", CASES)
def test_separable_factors_reproduce_the_assembled_matrices(case):
    model = model_for(case)
    A_u, B_u, A_v, B_v = mb.separable_matrices(model.kronecker_factors())
    M, _, K = model.matrices()
    K_sep = np.kron(A_u, B_v) + np.kron(B_u, A_v)
    assert np.abs(K_sep - K.toarray()).max() <= 1e-12 * np.abs(K).max()
    assert np.abs(MATERIAL.mass * np.kron(B_u, B_v) - M.toarray()).max() <= 1e-13 * np.abs(M).max()


@pytest.mark.parametrize("case", CASES)
def test_separable_and_dense_paths_agree(case):
    model = model_for(case)
    dense, sep = model.modal_basis("dense"), model.modal_basis("separable")
    assert sep.kind == "separable" and sep.complete
    lam = np.sort(sep.lam)
    assert np.abs(lam - dense.lam).max() <= 1e-10 * dense.lam.max()
    # the Kronecker modes are M-orthonormal and diagonalise K
    M, _, K = model.matrices()
    phi = sep.columns(np.arange(sep.size))
    assert np.abs(phi.T @ (M @ phi) - np.eye(sep.size)).max() < 1e-10
    assert np.abs(phi.T @ (K @ phi) - np.diag(sep.lam)).max() < 1e-10 * lam.max()
    # static response through all modes
    F = model.load_vector(sd.Point(0.3, 0.6, (0.0, 0.0, 1.0)))
    if not model.constraints.unconstrained:
        exact = model.static(sd.Point(0.3, 0.6, (0.0, 0.0, 1.0))).d_free
        for basis in (sep, dense):
            assert np.abs(basis.static(F) - exact).max() <= 1e-10 * np.abs(exact).max()
    # dynamic control points
    a = model.dynamic(LOAD, 1.0, eigensolver="dense").control_points(TIMES)
    b = model.dynamic(LOAD, 1.0, eigensolver="separable").control_points(TIMES)
    scale = np.abs(a - model.surface.control_points).max()
    assert np.abs(a - b).max() <= 1e-10 * scale


def test_auto_chooses_separable_above_the_dense_limit(monkeypatch):
    model = model_for("open clamped")
    assert spectrum.choose(model) == "dense"                 # small nets: the dense reference
    monkeypatch.setattr(mb, "DENSE_LIMIT", 10)
    assert spectrum.choose(model) == "separable"
    reference = model.modal_basis("dense")
    lam, phi = model.eigen(5)
    assert np.allclose(lam, reference.lam[:5], rtol=1e-10, atol=0)
    M = model.matrices()[0]
    assert np.allclose(phi.T @ (M @ phi), np.eye(5), atol=1e-10)
    sol = model.dynamic(LOAD, 1.0)
    assert sol.basis.kind == "separable"


@pytest.mark.parametrize("change, words", [
    ({"material": sd.Material(w10=1, w01=1, w20=1, w11=1, w02=1)}, "w11"),
    ({"mass_matrix": "lumped"}, "lumped"),
    ({"fixed": "disc"}, "rectangular"),
])
def test_separable_path_is_refused_with_the_reason(change, words, monkeypatch):
    surf = sd.shapes.plane(cells=(8, 8))
    fixed = None
    if change.get("fixed") == "disc":
        g = surf.basis_u.greville()
        fixed = (g[:, None] - 0.5) ** 2 + (g[None, :] - 0.5) ** 2 > 0.3**2
    model = sd.Model(surf, change.get("material", MATERIAL), boundary="clamped", fixed=fixed,
                     mass_matrix=change.get("mass_matrix", "consistent"))
    assert words in spectrum.separable_reason(model)
    with pytest.raises(InputError, match=words):
        model.dynamic(LOAD, 1.0, eigensolver="separable")
    monkeypatch.setattr(mb, "DENSE_LIMIT", 10)
    assert spectrum.choose(model) == "dense"
    assert spectrum.choose(model, truncated=True) == "sparse"


def general_model(**kwargs):
    """A rectangular plate (no repeated frequencies) with the twist term: not separable."""
    surf = sd.shapes.plane(size=(1.0, 0.77), cells=(9, 7))
    material = sd.Material(mass=1.3, damping=0.2, w10=3.0, w01=3.0, w20=0.4, w11=0.4, w02=0.4)
    return sd.Model(surf, material, **kwargs)


def test_sparse_lanczos_matches_the_lowest_dense_modes():
    model = general_model(boundary="clamped")
    dense = model.modal_basis("dense")
    sparse = model.modal_basis("sparse", modes=10)
    assert sparse.size == 10 and not sparse.complete
    assert np.abs(sparse.lam - dense.lam[:10]).max() <= 1e-10 * dense.lam[9]
    assert np.isclose(sparse.first_omitted, dense.lam[10], rtol=1e-10)
    M = model.matrices()[0]
    overlap = np.abs(sparse.phi.T @ (M @ dense.phi[:, :10]))   # same modes up to sign
    assert np.abs(overlap - np.eye(10)).max() < 1e-7


def test_sparse_lanczos_on_a_free_surface_finds_the_rigid_modes():
    model = general_model(boundary="free")
    sparse = model.modal_basis("sparse", modes=5)
    dense = model.modal_basis("dense")
    assert np.sum(sparse.lam < 1e-9 * dense.lam.max()) == 1      # translation (tension)
    assert np.abs(sparse.lam[1:] - dense.lam[1:5]).max() <= 1e-9 * dense.lam[4]
    sol = model.dynamic(sd.Point(0.5, 0.4, (0, 0, 1), profile=sd.Step(0.0, 0.3)), 0.5,
                        eigensolver="sparse", modes=5)
    assert sol.truncation["static_correction"] is False


def test_omega_cutoff_keeps_exactly_the_modes_below_it():
    model = general_model(boundary="clamped")
    dense = model.modal_basis("dense")
    cut = 0.5 * (np.sqrt(dense.lam[13]) + np.sqrt(dense.lam[14]))
    for solver in ("dense", "sparse"):
        basis = model.modal_basis(solver, omega_max=cut)
        assert basis.size == 14
        assert np.isclose(basis.first_omitted, dense.lam[14], rtol=1e-10)


@pytest.mark.parametrize("solver", ["dense", "sparse"])
def test_mode_acceleration_is_exact_in_the_static_limit(solver):
    """Heavily damped, long after the step: every mode is at rest, d = K⁻¹F exactly."""
    surf = sd.shapes.plane(size=(1.0, 0.77), cells=(9, 7))
    material = sd.Material(mass=1.0, damping=400.0, w10=3.0, w01=3.0, w20=0.4, w11=0.4, w02=0.4)
    model = sd.Model(surf, material, boundary="clamped")
    load = sd.Point(0.3, 0.6, (0.0, 0.0, -1.0))
    static = model.static(load).control_points()
    sol = model.dynamic(load, 60.0, eigensolver=solver, modes=4)
    late = sol.control_points(60.0)
    assert np.abs(late - static).max() <= 1e-10 * np.abs(static - surf.control_points).max()
    assert sol.truncation["static_residual"] < 1e-10
    # without the static part the truncated modes alone miss a visible share of it
    modal_only = sol.basis.expand(sol.modal(np.array([60.0]))[0])[0]
    assert np.abs(modal_only - sol.state(60.0)[0][0]).max() > 1e-3 * np.abs(static - surf.control_points).max()


@pytest.mark.parametrize("case", ["general", "separable"])
def test_truncation_indicator_bounds_the_error_of_a_step_load(case):
    """Omitted mode i: exact g/λ (1 - P11) vs g/λ, so ‖e‖_M <= max|P11| ‖R‖_M, |P11| <= 1/√(1-ζ²)."""
    if case == "general":
        model = general_model(boundary="clamped")
        solver = "sparse"
    else:
        model = model_for("open clamped", sd.Material(mass=1.0, damping=0.4, w10=2.0, w01=1.0,
                                                      w20=0.5, w02=0.3))
        solver = "separable"
    load = sd.Point(0.3, 0.45, (0.0, 0.0, -1.0))
    t = np.linspace(0.0, 1.0, 41)
    exact = model.dynamic(load, 1.0, eigensolver="dense").state(t)[0]
    static_norm = None
    M = model.matrices()[0]
    previous = np.inf
    for k in (4, 10, 20):
        sol = model.dynamic(load, 1.0, eigensolver=solver, modes=k)
        report = sol.truncation
        assert report["modes"] == k and report["n_free"] == model.n_free
        assert report["omega_first_omitted"] >= report["omega_max_kept"]
        err = sol.state(t)[0] - exact
        static = model.static(load).d_free
        static_norm = np.sqrt(np.sum(static * (M @ static)))
        err_m = max(np.sqrt(np.sum(e * (M @ e))) for e in err) / static_norm
        zeta = model.material.damping / (2 * report["omega_first_omitted"])
        assert err_m <= report["omitted_static"] / np.sqrt(1 - zeta**2) * (1 + 1e-9)
        assert err_m < previous
        previous = err_m


def test_frames_in_chunks_equal_frames_at_once(monkeypatch):
    model = model_for("uniform mixed edges")
    sol = model.dynamic(LOAD, 1.0, eigensolver="separable")
    whole = sol.control_points(TIMES)
    monkeypatch.setattr(type(sol), "chunk_entries", 1)
    # Chunking changes the shapes of the BLAS products, and BLAS may then sum in another
    # order (blocking/SIMD kernels differ by CPU and library): equal only to rounding,
    # a few ulps of the largest entry, never bit for bit.
    np.testing.assert_allclose(sol.control_points(TIMES), whole,
                               rtol=0, atol=1e-13 * np.abs(whole).max())
    v = sol.state(TIMES)[1]
    vr = model.dynamic(LOAD, 1.0, eigensolver="dense").state(TIMES)[1]
    assert np.abs(v - vr).max() <= 1e-10 * np.abs(vr).max()


def test_frames_sample_the_surface_by_one_sparse_product():
    model = model_for("open clamped")
    sol = model.dynamic(LOAD, 1.0)
    frames = sol.frames(TIMES, resolution=(7, 9))
    u, v = model.surface.sample_parameters((7, 9))
    for f, t in enumerate(TIMES):
        surf = model.surface.with_control_points(sol.control_points(t))
        assert np.allclose(frames.points[f], surf.evaluate_grid(u, v), atol=1e-14, rtol=0)
    # same formula, possibly other product shapes (chunks): equal to rounding, not bitwise
    cp = sol.control_points(TIMES)
    np.testing.assert_allclose(frames.control_points, cp, rtol=0, atol=1e-13 * np.abs(cp).max())
    assert sol.frames(TIMES).points is None


def test_modes_of_a_structured_basis_expand_like_the_explicit_matrix():
    model = model_for("open free region")
    sep = model.modal_basis("separable").restricted(np.array([3, 0, 17, 8]))
    phi = sep.columns(np.arange(sep.size))
    Q = np.random.default_rng(1).normal(size=(2, sep.size, 3))
    assert np.allclose(sep.expand(Q), np.einsum("nk,fkc->fnc", phi, Q), atol=1e-13)
    F = np.random.default_rng(2).normal(size=(model.n_free, 3))
    assert np.allclose(sep.project(F), phi.T @ F, atol=1e-13)


@pytest.mark.parametrize("options, words", [
    ({"modes": 3, "omega_max": 10.0}, "either"),
    ({"modes": 0}, "modes"),
    ({"omega_max": -1.0}, "omega_max"),
    ({"omega_max": 1e-3}, "no mode"),
    ({"eigensolver": "qr"}, "unknown eigensolver"),
    ({"eigensolver": "sparse"}, "lowest modes"),
])
def test_bad_truncation_requests(options, words):
    model = general_model(boundary="clamped")
    with pytest.raises(InputError, match=words):
        model.dynamic(LOAD, 1.0, **options)


def test_huge_general_nets_ask_for_a_truncation(monkeypatch):
    model = general_model(boundary="clamped")
    reference = model.modal_basis("dense").lam[:4]
    monkeypatch.setattr(mb, "DENSE_LIMIT", 10)
    monkeypatch.setattr(mb, "DENSE_MAX", 20)
    with pytest.raises(InputError, match="modes=k or omega_max="):
        model.dynamic(LOAD, 1.0)
    lam, phi = model.eigen(4)                     # the lowest modes still come (sparse)
    assert phi.shape == (model.n_free, 4)
    assert np.allclose(lam, reference, rtol=1e-10)


def test_eigen_residual_is_small_for_every_strategy():
    model = model_for("open clamped")
    M, _, K = model.matrices()
    for basis in (model.modal_basis("dense"), model.modal_basis("separable"),
                  model.modal_basis("sparse", modes=6)):
        assert mb.eigen_residual(K, M, basis) < 1e-10
    assert isinstance(K, sp.spmatrix) or sp.issparse(K)
