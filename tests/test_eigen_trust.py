"""The residual guard's bound ``η = ‖Kφ − λMφ‖_{M⁻¹}`` against an independent dense
solve, and the shell's solves under the library's BLAS thread limit."""

import numpy as np
import scipy.linalg as sla
import pytest

import splinedeform as sd
from splinedeform import threads
from splinedeform.physics.shell import ShellMaterial
from splinedeform.physics.shell_model import ShellModel
from splinedeform.solvers import eigen_trust

MATERIAL = ShellMaterial(E=2e5, nu=0.3, thickness=0.05)


def shell() -> ShellModel:
    surface = sd.shapes.plane(cells=(6, 5))
    return ShellModel(surface, MATERIAL, {"u0": "clamped", "u1": "pinned"})


def test_eta_is_the_m_inverse_norm_of_the_residual_and_bounds_the_eigenvalue_error():
    model = shell()
    M_r, _, K_r = model.matrices()
    K, M = K_r.toarray(), M_r.toarray()
    lam, phi = sla.eigh(K, M)
    rng = np.random.default_rng(3)
    # perturbed pairs: a residual well above round-off, so η is measured, not noise
    trial = phi[:, :6] + 1e-4 * rng.standard_normal((K.shape[0], 6))
    mu = lam[:6] * (1 + 1e-5)
    eta, _ = eigen_trust.residual_bounds(K_r, M_r, mu, trial)
    x = trial / np.sqrt(np.einsum("ik,ik->k", trial, M @ trial))
    r = K @ x - (M @ x) * mu
    reference = np.sqrt(np.einsum("ik,ik->k", r, np.linalg.solve(M, r)))
    # the banded Cholesky and LAPACK's dense LU solve the same M: round-off of cond(M) ε,
    # cond(M) ~ 1e3 for cubic splines, so 1e-9 relative is generous and still sharp
    assert np.allclose(eta, reference, rtol=1e-9, atol=0)
    # Parlett §15: some eigenvalue lies within η of μ (all six here: perturbations are small)
    assert np.all(np.abs(lam[None, :] - mu[:, None]).min(axis=1) <= eta)


def test_the_shell_solves_run_with_the_library_blas_threads(monkeypatch):
    threadpoolctl = pytest.importorskip("threadpoolctl")
    seen = []
    factorise = eigen_trust.factorise

    def recording(M, *args):
        seen.append({i["num_threads"] for i in threadpoolctl.threadpool_info()
                     if i["user_api"] == "blas"})
        return factorise(M, *args)

    monkeypatch.setattr(eigen_trust, "factorise", recording)
    monkeypatch.delenv(threads.ENVIRONMENT, raising=False)
    model = shell()
    omega = model.frequencies(4)
    assert seen == [{1}]             # the residual guard ran, inside the library's limit
    assert np.all(np.diff(omega) >= 0) and omega[0] > 0
