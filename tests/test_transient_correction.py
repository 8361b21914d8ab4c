"""The transient correction of the omitted modes (solvers/transient_correction.py) against
the modal closed form with every mode of a small plate."""

import numpy as np
import pytest
import scipy.linalg as sla

import splinedeform as sd
from splinedeform.solvers.factor import factorise
from splinedeform.solvers.transient_correction import (TransientCorrection, fitted,
                                                       free_response, over_damped_from)

PLATE = sd.Material(mass=1.0, damping=0.8, rayleigh=5e-4, w10=10.0, w01=10.0, w20=1.0,
                    w11=1.0, w02=1.0)


@pytest.fixture(scope="module")
def plate():
    model = sd.Model(sd.shapes.plane(cells=(16, 16)), PLATE, boundary="clamped")
    M, _, K = model.matrices()
    lam, phi = sla.eigh(K.toarray(), M.toarray())
    return K, M, lam, phi


def test_free_response_solves_its_equation():
    """P_11 of q'' + c q' + λ q = 0, q(0) = 1, q'(0) = 0 in the three regimes, against
    the equation by central differences (step h = 1e-5 τ: error O(h²) ≈ 1e-8 relative)."""
    for lam, gamma, beta in [(100.0, 0.8, 0.0), (100.0, 20.0, 0.0), (1e8, 0.8, 5e-4)]:
        c = gamma + beta * lam
        tau = np.array([0.3, 1.0, 3.0]) / np.sqrt(lam)
        h = 1e-5 * tau
        p = [free_response(lam, gamma, beta, tau + s * h) for s in (-1, 0, 1)]
        residual = (p[2] - 2 * p[1] + p[0]) / h**2 + c * (p[2] - p[0]) / (2 * h) + lam * p[1]
        assert np.abs(residual).max() <= 1e-4 * lam   # O(h²) differences, relative to λ q
    assert free_response(1e4, 0.8, 5e-4, 0.0) == 1.0


@pytest.mark.parametrize("gamma, beta", [(0.8, 2e-3), (8.0, 2e-3), (0.8, 5e-3), (0.05, 0.0)])
def test_the_omitted_modes_follow_their_closed_form_within_the_bound(plate, gamma, beta):
    """Point load at one coordinate, switched on at 0; times 1e-3 β .. 20 β after it. The
    correction is exact per mode but for p_τ − P_11, so its M-norm error is within
    ‖R‖_M E_d (plus rounding: R and the reference are differences of terms of the size of
    ‖K⁻¹F‖_M, measured 1e-14 of it, allowed 1e-12); where every omitted mode
    is over-damped it is far below the static correction's error (here by 1e3 at least)."""
    K, M, lam, phi = plate
    n = K.shape[0]
    lam_o = over_damped_from(gamma, beta)
    m = int(np.searchsorted(lam, lam_o)) if np.isfinite(lam_o) else n // 2
    assert 10 <= m < n - 20                           # the case: modes omitted above λ_o
    F = np.zeros((n, 1))
    F[n // 2 + 5] = 1.0
    g = phi.T @ F
    statics = g / lam[:, None]
    full = factorise(K).solve(F)
    R = full - phi[:, :m] @ statics[:m]
    correction = TransientCorrection(factorise(K).solve, M, phi[:, :m], float(lam[m]),
                                     gamma, beta, np.array([0.0]), R[None])
    scale = max(beta, 1e-3)
    taus = scale * np.array([1e-3, 0.1, 1.0, 4.0, 20.0])
    exact = phi[:, m:] @ (statics[m:] * (1 - free_response(lam[m:, None], gamma, beta,
                                                           taus[None, :])))
    got = correction(taus)[:, :, 0].T
    norm = lambda x: np.sqrt(np.sum(x * (M @ x), axis=0))
    error, static_error, r = norm(got - exact), norm(R - exact), norm(R)[0]
    bound = r * fitted(float(lam[m]), gamma, beta, taus)[1]
    assert np.all(error <= bound + 1e-12 * norm(full)[0])
    if beta > 0:
        assert np.all(error[:4] <= 1e-3 * static_error[:4])
    else:                                             # no over-damped modes: the static one
        np.testing.assert_allclose(got, np.repeat(R, taus.size, axis=1), rtol=0,
                                   atol=1e-15 * np.abs(R).max())
    assert np.all(correction(np.array([-1.0, 0.0])) == 0.0)   # H(0) = 0: nothing before


def test_over_damped_from_is_the_root_of_critical_damping():
    gamma, beta = 0.8, 5e-4
    lam_o = over_damped_from(gamma, beta)
    # (γ + βλ)² = 4λ at λ_o, within rounding of the quadratic formula (1e-12 relative)
    assert abs((gamma + beta * lam_o) ** 2 - 4 * lam_o) <= 1e-12 * 4 * lam_o
    assert (gamma + beta * 2 * lam_o) ** 2 > 8 * lam_o
    assert over_damped_from(0.8, 0.0) == np.inf


def test_under_damped_omitted_modes_follow_their_closed_form_within_the_bound(plate):
    """Omitted modes from below the over-damped range (λ_{m+1} < λ_o: some of them
    oscillate), degree 16, times 0.05 β .. 20 β after the jump: the M-norm error is
    within ‖R‖_M E_d (plus rounding, 1e-12 of ‖K⁻¹F‖_M as above), and where the fit is
    made it is far below the static correction's error (by 1e3 at least: the bench plate's
    parameters, where the fit meets 1e-8 with fewer modes than the over-damped range)."""
    K, M, lam, phi = plate
    n = K.shape[0]
    gamma, beta = 0.8, 5e-4
    m = int(np.searchsorted(lam, 0.2 * over_damped_from(gamma, beta)))
    assert 10 <= m < n - 20 and lam[m] < over_damped_from(gamma, beta)   # under-damped
    F = np.zeros((n, 1))
    F[n // 2 + 5] = 1.0
    statics = (phi.T @ F) / lam[:, None]
    full = factorise(K).solve(F)
    R = full - phi[:, :m] @ statics[:m]
    correction = TransientCorrection(factorise(K).solve, M, phi[:, :m], float(lam[m]),
                                     gamma, beta, np.array([0.0]), R[None], degree=16)
    taus = beta * np.array([0.05, 0.5, 2.0, 8.0, 20.0])
    exact = phi[:, m:] @ (statics[m:] * (1 - free_response(lam[m:, None], gamma, beta,
                                                           taus[None, :])))
    got = correction(taus)[:, :, 0].T
    norm = lambda x: np.sqrt(np.sum(x * (M @ x), axis=0))
    error, static_error, r = norm(got - exact), norm(R - exact), norm(R)[0]
    coef, E = fitted(float(lam[m]), gamma, beta, taus, 16)
    assert np.all(error <= r * E + 1e-12 * norm(full)[0])
    made = np.any(coef != 0, axis=0)
    assert made[:3].all()                              # the fit is made just after the jump
    assert np.all(error[made] <= 1e-3 * static_error[made] + 1e-12 * norm(full)[0])


@pytest.mark.parametrize("gamma, beta", [(0.8, 5e-4), (8.0, 5e-4), (0.8, 2e-3), (20.0, 1e-4)])
def test_the_sampled_fit_error_bounds_its_supremum(gamma, beta):
    """E_d is MARGIN × the largest error on CHECK points plus ROUNDING; on 150 000 points
    of x (uniform and geometric towards 0) the error never exceeds it, for cut-offs
    λ_{m+1} from 1e3 to 1e9 (under- and over-damped omitted modes) and τ from 1e-3 β to
    50 β, degrees 8 and 16."""
    from splinedeform.solvers.transient_correction import _chebyshev

    x = np.unique(np.concatenate([np.linspace(0.0, 1.0, 100001),
                                  np.geomspace(1e-16, 1.0, 50000)]))
    taus = beta * np.geomspace(1e-3, 50.0, 7)
    for lam_next in np.geomspace(1e3, 1e9, 7):
        lam = lam_next / np.where(x > 0, x, 1.0)
        for degree in (8, 16):
            coef, E = fitted(lam_next, gamma, beta, taus, degree)
            for u, tau in enumerate(taus):
                if not np.any(coef[:, u]):
                    continue                           # the static bound: not a fit
                exact = np.where(x > 0, free_response(lam, gamma, beta, tau),
                                 np.exp(-tau / beta))
                sup = np.abs(_chebyshev(x, degree) @ coef[:, u] - exact).max()
                assert sup <= E[u], (lam_next, degree, tau)
