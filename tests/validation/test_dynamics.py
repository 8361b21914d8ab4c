"""Analytic (modal closed-form) dynamics against tight numerical integration and energy balance."""

import numpy as np
import pytest

import splinedeform as sd


def small_model(damping, knots="open", rayleigh=0.0):
    surf = sd.shapes.plane(size=(1.0, 1.0), cells=(4, 4), degree=3, knots=knots)
    mat = sd.Material(mass=1.0, damping=damping, rayleigh=rayleigh,
                      w10=1.0, w01=1.0, w20=0.01, w11=0.01, w02=0.01)
    return surf, sd.Model(surf, mat, boundary="clamped")


def regime_damping(model, regime):
    """γ making the lowest mode under-, critically or over-damped (μ = 1: c = γ)."""
    lam1 = model.eigen()[0][0]
    return {"under": 0.2 * np.sqrt(lam1), "critical": 2 * np.sqrt(lam1),
            "over": 8 * np.sqrt(lam1)}[regime]


LOADS = {
    "step": sd.Point(0.3, 0.6, (0.2, 0.0, -1.0), profile=sd.Step(0.1, 0.7)),
    "harmonic": sd.Uniform((0.0, 0.3, 1.0), profile=sd.Harmonic(7.0, 0.4)),
    "piecewise": sd.Pressure(0.5, profile=sd.Piecewise([(0.0, 1.0), (0.4, -0.5), (0.9, 0.25)])),
}


@pytest.mark.parametrize("knots", ["open", "uniform"])
@pytest.mark.parametrize("regime", ["undamped", "under", "critical", "over"])
@pytest.mark.parametrize("load_name", sorted(LOADS))
def test_analytic_matches_dop853(knots, regime, load_name):
    _, probe = small_model(0.0, knots)
    gamma = 0.0 if regime == "undamped" else regime_damping(probe, regime)
    surf, model = small_model(gamma, knots)
    load = LOADS[load_name]
    t = np.linspace(0.0, 1.5, 31)
    exact = model.dynamic(load, 1.5).control_points(t) - surf.control_points
    ref = model.dynamic(load, 1.5, method="dop853", times=t, rtol=1e-11,
                        atol=1e-14).control_points(t) - surf.control_points
    assert np.abs(exact - ref).max() <= 1e-7 * np.abs(ref).max()


def test_initial_conditions_and_rayleigh_damping():
    surf, model = small_model(0.3, rayleigh=1e-3)
    rng = np.random.default_rng(3)
    free = model.constraints.T @ rng.normal(size=(model.n_free, 3))
    d0 = 0.01 * free.reshape(surf.shape + (3,))
    v0 = 0.05 * (model.constraints.T @ rng.normal(size=(model.n_free, 3))).reshape(surf.shape + (3,))
    t = np.linspace(0, 1.0, 21)
    exact = model.dynamic(None, 1.0, initial_displacement=d0, initial_velocity=v0)
    ref = model.dynamic(None, 1.0, method="dop853", times=t, rtol=1e-11, atol=1e-14,
                        initial_displacement=d0, initial_velocity=v0)
    assert np.allclose(exact.control_points(0.0), surf.control_points + d0, atol=1e-14)
    assert np.allclose(exact.velocities(0.0), v0, atol=1e-12)
    scale = np.abs(d0).max()
    assert np.abs(exact.control_points(t) - ref.control_points(t)).max() < 1e-8 * scale


def test_stable_across_the_critical_damping_boundary():
    """Solutions at γ_crit (1 ± 1e-9) differ from the critical one by O(1e-9), not more."""
    _, probe = small_model(0.0)
    gc = regime_damping(probe, "critical")
    t = np.linspace(0, 2, 41)
    load = LOADS["step"]
    sols = [small_model(gc * (1 + e))[1].dynamic(load, 2.0).control_points(t)
            for e in (-1e-9, 0.0, 1e-9)]
    scale = np.abs(sols[1] - probe.surface.control_points).max()
    assert np.abs(sols[0] - sols[1]).max() < 1e-7 * scale
    assert np.abs(sols[2] - sols[1]).max() < 1e-7 * scale


@pytest.mark.parametrize("knots", ["open", "uniform"])
def test_undamped_energy_is_conserved(knots):
    _, model = small_model(0.0, knots)
    load = sd.Point(0.3, 0.6, (0.1, 0.0, -1.0)) + sd.Uniform((0, 0, 0.5))
    energy = model.dynamic(load, 5.0).energy(np.linspace(0.0, 5.0, 200))
    # E(0) = 0 (rest, no motion); the scale is the largest kinetic energy reached
    scale = energy.kinetic.max()
    assert scale > 0
    assert np.abs(energy.total - energy.total[0]).max() <= 1e-9 * scale


def test_damped_energy_never_increases():
    _, probe = small_model(0.0)
    _, model = small_model(regime_damping(probe, "under"))
    energy = model.dynamic(sd.Point(0.5, 0.5, (0, 0, -1)), 5.0).energy(np.linspace(0, 5, 400))
    assert np.all(np.diff(energy.total) <= 1e-12 * energy.kinetic.max())
    assert energy.total[-1] < energy.total[0] - 0.5 * energy.kinetic.max()


def test_damped_step_tends_to_the_static_solution():
    _, probe = small_model(0.0)
    _, model = small_model(regime_damping(probe, "over"))
    load = sd.Point(0.4, 0.5, (0, 0, -1))
    late = model.dynamic(load, 200.0).control_points(200.0)
    assert np.allclose(late, model.static(load).control_points(), atol=1e-10)


def test_unconstrained_surface_drifts_rigidly():
    """λ = 0 modes: a free surface under a uniform load accelerates as a whole, d = F t²/(2 m)."""
    surf = sd.shapes.plane(cells=(3, 3))
    model = sd.Model(surf, sd.Material(mass=2.0, w20=1, w11=1, w02=1))
    t = np.array([0.0, 0.5, 1.0, 3.0])
    d = model.dynamic(sd.Uniform((0, 0, 1.0)), 3.0).control_points(t) - surf.control_points
    expected = 1.0 / 2.0 * t**2 / 2
    assert np.allclose(d[..., 2], expected[:, None, None], atol=1e-12)
    assert np.allclose(d[..., :2], 0, atol=1e-12)


@pytest.mark.parametrize("method, options, tol", [
    ("newmark", {"dt": 2e-4}, 5e-5),
    ("rk45", {"rtol": 1e-10, "atol": 1e-13}, 1e-6),
    ("radau", {"rtol": 1e-10, "atol": 1e-13}, 1e-6),
    ("bdf", {"rtol": 1e-9, "atol": 1e-13}, 1e-4),
])
def test_numerical_methods_agree_with_the_analytic_solution(method, options, tol):
    _, probe = small_model(0.0)
    surf, model = small_model(regime_damping(probe, "under"))
    load = LOADS["step"]
    t = np.linspace(0, 1.0, 11)
    exact = model.dynamic(load, 1.0).control_points(t) - surf.control_points
    num = model.dynamic(load, 1.0, method=method, times=t, **options).control_points(t)
    assert np.abs(num - surf.control_points - exact).max() <= tol * np.abs(exact).max()


def test_newmark_is_second_order():
    surf, model = small_model(0.5)
    load = LOADS["harmonic"]
    t = np.linspace(0, 1.0, 5)
    exact = model.dynamic(load, 1.0).control_points(t)
    errs = [np.abs(model.dynamic(load, 1.0, method="newmark", times=t, dt=dt).control_points(t)
                   - exact).max() for dt in (4e-3, 2e-3, 1e-3)]
    rates = np.log2(np.array(errs[:-1]) / np.array(errs[1:]))
    assert np.all(np.abs(rates - 2) < 0.2), rates
