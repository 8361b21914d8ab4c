"""Closed-form modal responses against explicit formulas and scipy's expm."""

import numpy as np
import pytest
import scipy.linalg as sla
from hypothesis import given, settings
from hypothesis import strategies as st

from splinedeform.solvers.analytic import (ModalResponse, harmonic_response, phi1, phi2,
                                            propagator, step_response)


@settings(max_examples=200, deadline=None)
@given(lam=st.floats(0, 1e4), c=st.floats(0, 300), tau=st.floats(0, 5))
def test_propagator_equals_matrix_exponential(lam, c, tau):
    A = np.array([[0.0, 1.0], [-lam, -c]])
    P = sla.expm(A * tau)
    got = np.array(propagator(lam, c, tau)).reshape(2, 2)
    scale = max(1.0, np.abs(P).max())
    assert np.allclose(got, P, rtol=1e-9, atol=1e-12 * scale * max(1, lam))


def test_propagator_at_exact_regime_boundaries():
    # critical: e^{-aτ}(1 + aτ) etc.
    lam, c, tau = 4.0, 4.0, 0.7
    a = 2.0
    p11, p12, p21, p22 = propagator(lam, c, tau)
    assert p11 == pytest.approx(np.exp(-a * tau) * (1 + a * tau), rel=1e-14)
    assert p12 == pytest.approx(np.exp(-a * tau) * tau, rel=1e-14)
    # continuity through the boundary
    for eps in (1e-6, 1e-10, 1e-14):
        for sign in (-1, 1):
            assert np.allclose(propagator(lam, c * (1 + sign * eps), tau),
                               (p11, p12, p21, p22), rtol=0, atol=10 * eps + 1e-15)


def test_step_response_closed_forms():
    tau = np.linspace(0, 3, 7)
    # undamped: (1 - cos ωτ)/ω²
    q, v = step_response(9.0, 0.0, tau)
    assert np.allclose(q, (1 - np.cos(3 * tau)) / 9, atol=1e-15)
    assert np.allclose(v, np.sin(3 * tau) / 3, atol=1e-15)
    # λ = 0, c > 0: (τ - (1 - e^{-cτ})/c)/c
    q, v = step_response(0.0, 2.0, tau)
    assert np.allclose(q, (tau - (1 - np.exp(-2 * tau)) / 2) / 2, atol=1e-15)
    # λ = 0, c = 0: τ²/2; and zero before the switch
    q, _ = step_response(0.0, 0.0, np.array([-1.0, 0.0, 2.0]))
    assert np.allclose(q, [0, 0, 2.0])


def test_phi_functions_are_accurate_near_zero():
    z = np.array([-1e-12, -1e-6, 1e-8, 0.3, -0.49, 0.51, -40.0])
    assert np.allclose(phi1(z), np.expm1(z) / z, rtol=1e-14)
    exact = np.array([0.5 + zz / 6 + zz**2 / 24 for zz in z[:3]])
    assert np.allclose(phi2(z[:3]), exact, rtol=1e-14)
    assert np.allclose(phi2(z[3:]), (np.expm1(z[3:]) - z[3:]) / z[3:] ** 2, rtol=1e-12)


def test_harmonic_response_away_from_and_at_resonance():
    t = np.linspace(0, 4, 9)
    # undamped, off resonance: sin(Ωt)/(λ-Ω²) - Ω sin(ωt)/(ω(λ-Ω²))
    lam, om = 4.0, 3.0
    q, _ = harmonic_response(lam, 0.0, om, 0.0, t)
    assert np.allclose(q, (np.sin(om * t) - om / 2 * np.sin(2 * t)) / (lam - om**2), atol=1e-14)
    # resonance: (sin ωt - ωt cos ωt)/(2ω²)
    q, _ = harmonic_response(9.0, 0.0, 3.0, 0.0, t)
    assert np.allclose(q, (np.sin(3 * t) - 3 * t * np.cos(3 * t)) / 18, atol=1e-14)


def test_modal_response_superposes_jumps():
    lam, c = np.array([4.0, 0.0]), np.array([0.5, 1.0])
    g = np.ones((2, 3))
    r = ModalResponse(lam, c, np.zeros((2, 3)), np.zeros((2, 3)), [(0.0, g), (1.0, -g)], [])
    t = np.array([0.5, 2.0])
    Q, _ = r(t)
    s0, _ = step_response(lam, c, t[:, None])
    s1, _ = step_response(lam, c, t[:, None] - 1.0)
    assert np.allclose(Q[..., 0], s0 - s1)


def _mp_undamped_harmonic(lam, omega, phase, t):
    """High-precision reference: ``q'' + λq = sin(Ωt+φ)`` from rest, closed form in mpmath.

    ``q = [Ω sin(ωt) cos φ/ω + cos(ωt) sin φ - sin(Ωt+φ)] / (Ω² - λ)`` evaluated with 60 digits,
    so the cancellation near resonance costs nothing at double-precision tolerance.
    """
    import mpmath
    with mpmath.workdps(60):
        lam, omega, phase, t = (mpmath.mpf(float(x)) for x in (lam, omega, phase, t))
        w = mpmath.sqrt(lam)
        num = (omega * mpmath.sin(w * t) * mpmath.cos(phase) / w + mpmath.cos(w * t) * mpmath.sin(phase)
               - mpmath.sin(omega * t + phase))
        return float(num / (omega**2 - lam))


@pytest.mark.parametrize("delta", [0.0, 1e-16, 1e-14, 1e-12, 1e-11, 1e-10, 1e-8, 1e-6, 1e-3, -1e-12,
                                   -1e-10])
def test_near_resonant_undamped_harmonic_matches_high_precision(delta):
    # Ω = ω(1+δ) across the band around resonance; the Duhamel divided-difference form has no
    # cancellation, so the error stays at round-off of the response scale. Tolerance 1e-10
    # relative to max|q| (which grows like t/(2ω) at resonance): the stated requirement.
    pytest.importorskip("mpmath")
    lam, phase = 2.7**2, 0.3
    omega = 2.7 * (1.0 + delta)
    t = np.linspace(0.0, 40.0, 57)
    q, _ = harmonic_response(lam, 0.0, omega, phase, t)
    if delta == 0.0:
        # exact resonance: cos φ (sin ωt - ωt cos ωt)/(2ω²) + sin φ t sin(ωt)/(2ω)
        ref = np.array([_mp_resonant(2.7, phase, tk) for tk in t])
    else:
        ref = np.array([_mp_undamped_harmonic(lam, omega, phase, tk) for tk in t])
    scale = np.abs(ref).max()
    assert np.abs(q - ref).max() <= 1e-10 * scale


def _mp_resonant(w, phase, t):
    import mpmath
    with mpmath.workdps(60):
        w, phase, t = mpmath.mpf(w), mpmath.mpf(phase), mpmath.mpf(float(t))
        q = (mpmath.cos(phase) * (mpmath.sin(w * t) - w * t * mpmath.cos(w * t)) / (2 * w * w)
             + mpmath.sin(phase) * t * mpmath.sin(w * t) / (2 * w))
        return float(q)


def test_near_resonant_lightly_damped_velocity_matches_derivative():
    # the velocity of the divided-difference form is the derivative of its displacement:
    # central difference with h = 1e-5 has error ~h²|q'''| ≈ 1e-9 of the response scale.
    lam, c, omega = 4.0, 1e-9, 2.0 * (1 + 1e-11)
    t = np.linspace(1.0, 30.0, 11)
    h = 1e-5
    qp, _ = harmonic_response(lam, c, omega, 0.2, t + h)
    qm, _ = harmonic_response(lam, c, omega, 0.2, t - h)
    _, v = harmonic_response(lam, c, omega, 0.2, t)
    assert np.abs(v - (qp - qm) / (2 * h)).max() <= 1e-8 * np.abs(v).max()
