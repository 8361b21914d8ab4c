"""The static correction of a truncated sculpting basis follows the dynamics: the page adds
``r_a ⊗ z_a(t)``, ``z_a`` the force seen through the highest kept mode
(:func:`splinedeform.sculpt.correction.follower`), never more than the omitted modes have
reached. Checked against every mode kept (the whole dynamics) and against the closed form of
the creep under heavy damping; the static limit stays exact."""

from __future__ import annotations

import numpy as np

import splinedeform as sd
from splinedeform.sculpt import Push, sculpt_basis
from splinedeform.sculpt.correction import follower, static_correction
from splinedeform.sculpt.state import modal_history

R = 9


def _sheet(damping: float) -> sd.Model:
    surf = sd.shapes.plane(size=(1.0, 1.0), cells=(5, 5))
    mat = sd.Material(w10=1, w01=1, w20=0.01, w11=0.01, w02=0.01, damping=damping)
    return sd.Model(surf, mat, boundary="clamped")


def _at(basis, index: int) -> tuple[float, float]:
    return float(basis.samples_u[index // R]), float(basis.samples_v[index % R])


def test_heavy_damping_the_correction_does_not_run_ahead_of_the_dynamics():
    model = _sheet(1e8)
    full = sculpt_basis(model, R)                      # every mode: the whole dynamics
    k = 8
    basis = sculpt_basis(model, R, k)
    assert k < model.n_free
    a = 4 * R + 4
    u, v = _at(basis, a)
    P, hold = (0.0, 0.0, -1.0), 0.6
    pushes = [Push(u, v, P, 0.0)]
    truth = (full.phi_samples @ modal_history(full, pushes, [hold])[0])[a, 2]
    # over-damped creep (c = 1e8, every λ_j ≤ ~1e4): q_j ≈ φ_j(a) P t / c, so the
    # point moves Σ_j φ_j(a)² t / c; the neglected terms are O(λ_j / c²) relative: 1e-3 is loose
    phi_a = full.phi_samples[a]
    assert abs(truth - (-np.sum(phi_a ** 2) * hold / 1e8)) <= 1e-3 * abs(truth)
    column = static_correction(basis).column(a)
    kept = (basis.phi_samples @ modal_history(basis, pushes, [hold])[0])[a, 2]
    ours = kept + column[a] * follower(basis, [(P, 0.0, np.inf)], hold)[2]
    instant = kept + column[a] * P[2]
    # the old instant correction: a static dent thousands of times the true creep
    assert abs(instant) > 1e3 * abs(truth)
    # the follower (the slowest omitted mode is no slower than the highest kept one) stays
    # below what the omitted modes reached; 1e-12 relative: round-off of the sums
    assert abs(ours) <= abs(truth) * (1 + 1e-12)
    assert abs(ours) >= abs(kept)


def test_light_damping_static_limit_stays_exact():
    model = _sheet(2.0)
    basis = sculpt_basis(model, R, 8)
    a = 3 * R + 5
    u, v = _at(basis, a)
    P = (0.2, 0.0, -1.0)
    t = 40.0                 # σ = 1 for every mode: the motion decayed by e^{-40}
    kept = basis.phi_samples @ modal_history(basis, [Push(u, v, P, 0.0)], [t])[0]
    ours = kept + static_correction(basis).column(a)[:, None] * follower(basis, [(P, 0.0, np.inf)], t)
    uu, vv = np.meshgrid(basis.samples_u, basis.samples_v, indexing="ij")
    static = model.static(sd.Point(u, v, P)).displacement(uu.ravel(), vv.ravel())
    # the static limit of mode acceleration is the static solve; e^{-40} and round-off: 1e-9
    assert np.max(np.abs(ours - static)) <= 1e-9 * np.max(np.abs(static))


def test_follower_of_a_released_push_is_the_difference_of_two_steps():
    basis = sculpt_basis(_sheet(2.0), R, 8)
    P = (0.0, 1.0, -2.0)
    z = follower(basis, [(P, 0.1, 0.5)], 0.9)
    lam, c = basis.lam[-1], basis.damping[-1]
    # closed form of the under-damped step: h = 1 - e^{-στ}(cos ωτ + σ/ω sin ωτ)
    sigma, omega = c / 2, np.sqrt(lam - c * c / 4)
    h = lambda tau: 1 - np.exp(-sigma * tau) * (np.cos(omega * tau) + sigma / omega * np.sin(omega * tau))
    # same formula through two evaluations: round-off of e^{-στ} and the trigonometry, 1e-12
    assert np.allclose(z, (h(0.8) - h(0.4)) * np.asarray(P), rtol=0, atol=1e-12)
