"""The modal sum used for sculpting equals Model.dynamic with the same pushes as step loads."""

import numpy as np
import pytest

import splinedeform as sd
from splinedeform.sculpt import Push, sculpt_basis


@pytest.mark.parametrize("damping, rayleigh", [(0.8, 0.0), (0.3, 2e-3), (40.0, 0.0)])
def test_superposed_pushes_equal_model_dynamic(damping, rayleigh):
    surf = sd.shapes.plane(size=(1.0, 1.0), cells=(5, 4))
    mat = sd.Material(w10=1.0, w01=1.0, w20=0.02, w11=0.02, w02=0.02, mass=1.0,
                      damping=damping, rayleigh=rayleigh)
    model = sd.Model(surf, mat, boundary={"u0": "clamped", "v1": "pinned"})
    pushes = [Push(0.4, 0.6, (0.0, 0.0, -1.0), 0.0, 0.35),
              Push(0.4, 0.6, (0.0, 0.2, -2.0), 0.35, 0.9),   # dragging: a new step
              Push(0.7, 0.2, (0.5, 0.0, 1.0), 0.5)]          # still held at the end
    basis = sculpt_basis(model, resolution=7)
    loads = [sd.Point(p.u, p.v, p.force, sd.Step(p.t_on, p.t_off)) for p in pushes]
    sol = model.dynamic(loads, t_end=2.0)
    uu, vv = np.meshgrid(basis.samples_u, basis.samples_v, indexing="ij")
    for t in (0.1, 0.35, 0.6, 1.3, 2.0):
        ours = basis.displacement(t, pushes)
        ref = sol.displacement(t, uu.ravel(), vv.ravel())
        # Both are the same closed form evaluated through different factorings (complex
        # roots here, the solver's own modal form there) of a complete dense basis: they
        # agree to round-off, amplified by at most ~1/min(λ) relative to the largest value.
        scale = np.max(np.abs(ref))
        assert scale > 1e-6
        assert np.max(np.abs(ours - ref)) <= 1e-10 * scale


def test_free_surface_refused():
    surf = sd.shapes.plane(cells=(3, 3))
    model = sd.Model(surf, sd.Material(w10=1, w01=1), boundary="free")
    with pytest.raises(sd.InputError, match="rigid-body"):
        sculpt_basis(model)


def test_payload_round_trip():
    from splinedeform.sculpt.export import decode, payload

    surf = sd.shapes.plane(cells=(4, 4))
    model = sd.Model(surf, sd.Material(w10=1, w01=1, damping=0.5), boundary="clamped")
    basis = sculpt_basis(model, resolution=6)
    data = payload(basis)
    assert data["grid"] == [6, 6] and data["modes"] == model.n_free
    # lam and damping travel as float64: exact copies of the same numbers
    assert np.allclose(decode(data["lam"], "<f8"), basis.lam, rtol=1e-15, atol=0)
    # phi travels as float32: relative rounding 2**-24 of each entry
    phi = decode(data["phi"]).reshape(36, -1)
    assert np.allclose(phi, basis.phi_samples, rtol=2**-23, atol=1e-30)
    rest = decode(data["rest"]).reshape(6, 6, 3)
    assert np.allclose(rest[-1, -1], surf.evaluate(np.array([1.0]), np.array([1.0]))[0], rtol=1e-6)


# -- the page's event-to-event propagation and the static correction ---------------------

def _plate(damping, rayleigh=0.0, cells=(5, 4)):
    surf = sd.shapes.plane(size=(1.0, 1.0), cells=cells)
    mat = sd.Material(w10=1.0, w01=1.0, w20=0.02, w11=0.02, w02=0.02, mass=1.0,
                      damping=damping, rayleigh=rayleigh)
    return sd.Model(surf, mat, boundary={"u0": "clamped", "v1": "pinned"})


PUSHES = [Push(0.4, 0.6, (0.0, 0.0, -1.0), 0.0, 0.35),
          Push(0.4, 0.6, (0.0, 0.2, -2.0), 0.35, 0.9),
          Push(0.7, 0.2, (0.5, 0.0, 1.0), 0.5)]


@pytest.mark.parametrize("damping, rayleigh", [(0.8, 0.0), (0.3, 2e-3), (40.0, 0.0)])
def test_event_propagation_equals_model_dynamic(damping, rayleigh):
    """The state carried from event to event (what the page does per frame) is the closed
    form of Model.dynamic with the pushes as step point loads."""
    from splinedeform.sculpt.state import modal_history

    model = _plate(damping, rayleigh)
    basis = sculpt_basis(model, resolution=7)
    loads = [sd.Point(p.u, p.v, p.force, sd.Step(p.t_on, p.t_off)) for p in PUSHES]
    sol = model.dynamic(loads, t_end=2.0)
    uu, vv = np.meshgrid(basis.samples_u, basis.samples_v, indexing="ij")
    times = [0.0, 0.1, 0.35, 0.6, 0.9, 1.3, 2.0]
    q = modal_history(basis, PUSHES, times)
    for n, t in enumerate(times):
        ref = sol.displacement(t, uu.ravel(), vv.ravel())
        scale = max(np.max(np.abs(ref)), 1e-3)
        # same closed form, different factoring (C, S series/trig/hyperbolic here): round-off
        # amplified by at most ~1/min(λ), as in the test above
        assert np.max(np.abs(basis.phi_samples @ q[n] - ref)) <= 1e-10 * scale


def test_propagation_near_critical_damping_is_continuous():
    """Modes at and around critical damping (s = σ² - λ through 0) follow one formula: the
    response to a unit step at c = 2√λ (1 + ε), ε from -1e-3 to 1e-3, agrees with the
    closed form 1/λ (1 - e^{-στ}(C + σ S)) evaluated with 50 digits (mpmath) to 1e-14
    (round-off of a few operations on numbers <= 1/λ = 0.25)."""
    import mpmath

    from splinedeform.sculpt.state import advance

    mpmath.mp.dps = 50
    eps = np.array([-1e-3, -1e-6, -1e-9, 0.0, 1e-9, 1e-6, 1e-3])
    lam = np.full(eps.size, 4.0)
    c = 2 * np.sqrt(lam) * (1 + eps)
    for tau in (0.01, 0.5, 3.0, 30.0):
        q, _ = advance(lam, c, np.zeros((eps.size, 3)), np.zeros((eps.size, 3)),
                       np.ones((eps.size, 3)), tau)
        for i in range(eps.size):
            sigma = mpmath.mpf(c[i]) / 2
            s = sigma ** 2 - 4
            if s == 0:
                C, S = mpmath.mpf(1), mpmath.mpf(tau)
            elif s > 0:
                C, S = mpmath.cosh(mpmath.sqrt(s) * tau), mpmath.sinh(mpmath.sqrt(s) * tau) / mpmath.sqrt(s)
            else:
                C, S = mpmath.cos(mpmath.sqrt(-s) * tau), mpmath.sin(mpmath.sqrt(-s) * tau) / mpmath.sqrt(-s)
            ref = float((1 - mpmath.exp(-sigma * tau) * (C + sigma * S)) / 4)
            assert np.max(np.abs(q[i] - ref)) <= 1e-14


def test_heavily_overdamped_propagation_stays_finite():
    from splinedeform.sculpt.state import advance

    lam, c = np.array([1.0]), np.array([1e4])
    q, v = advance(lam, c, np.zeros((1, 3)), np.zeros((1, 3)), np.ones((1, 3)), 1e3)
    # slow root r ≈ -λ/c = -1e-4: q = 1 - e^{-0.1} (1 + O(1e-8)) up to the fast part e^{-1e4·τ}
    assert np.all(np.isfinite(q)) and np.all(np.isfinite(v))
    assert np.allclose(q, 1 - np.exp(-1e3 * (5e3 - np.sqrt(25e6 - 1.0))), rtol=1e-9)


def test_static_correction_matches_truncated_model_dynamic():
    """Truncated basis + static correction equals Model.dynamic(..., modes=k), whose
    correction is the same mode acceleration, and is exact in the static limit."""
    from splinedeform.sculpt.correction import static_correction
    from splinedeform.sculpt.state import modal_history

    model = _plate(2.0)
    k = 6
    basis = sculpt_basis(model, resolution=7, modes=k)
    assert basis.lam.size == k < model.n_free
    correction = static_correction(basis)
    # pushes at sample points (the page snaps grabs to samples)
    a, b = 3 * 7 + 4, 5 * 7 + 1
    ua, va = basis.samples_u[a // 7], basis.samples_v[a % 7]
    ub, vb = basis.samples_u[b // 7], basis.samples_v[b % 7]
    pushes = [Push(ua, va, (0.0, 0.0, -1.0), 0.0, 0.7), Push(ub, vb, (0.3, 0.0, 1.0), 0.4)]
    loads = [sd.Point(p.u, p.v, p.force, sd.Step(p.t_on, p.t_off)) for p in pushes]
    sol = model.dynamic(loads, t_end=30.0, modes=k)
    uu, vv = np.meshgrid(basis.samples_u, basis.samples_v, indexing="ij")
    times = [0.2, 0.6, 1.0, 30.0]
    q = modal_history(basis, pushes, times)
    for n, t in enumerate(times):
        held = {}
        if t < 0.7:
            held[a] = (0.0, 0.0, -1.0)
        if t >= 0.4:
            held[b] = (0.3, 0.0, 1.0)
        ours = basis.phi_samples @ q[n] + correction.displacement(held)
        ref = sol.displacement(t, uu.ravel(), vv.ravel())
        # same formula through two factorings: round-off, scaled as above
        assert np.max(np.abs(ours - ref)) <= 1e-10 * np.max(np.abs(ref))
    # static limit (t = 30, the slowest mode decayed by e^{-30}): the full static solve
    static = model.static(loads[1], t=30.0).displacement(uu.ravel(), vv.ravel())
    ours = basis.phi_samples @ q[-1] + correction.displacement({b: (0.3, 0.0, 1.0)})
    assert np.max(np.abs(ours - static)) <= 1e-9 * np.max(np.abs(static))
