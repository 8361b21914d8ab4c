"""Modes chosen for a requested accuracy: the a-priori bound holds on three cases.

Reference: the same model with all modes (dense, exact to round-off). The error is measured
as the bound states it: the largest control-point coordinate difference, relative to the
largest static displacement ``max_t ‖K⁻¹F(t)‖_∞`` (from a sparse static solve), at the
requested times.
"""

import numpy as np
import pytest

import splinedeform as sd
from splinedeform.solvers import mode_count

@pytest.fixture(autouse=True)
def sparse_path_on_small_nets(monkeypatch):
    """These nets (361 to 841 free coordinates) are below the size where the automatic
    mode count starts its sparse path; lowered, they exercise it in a fraction of the time."""
    from splinedeform import modal_solve
    monkeypatch.setattr(modal_solve, "DENSE_BELOW", 256)


PLATE = sd.Material(mass=1.0, damping=0.8, rayleigh=5e-4, w10=10.0, w01=10.0, w20=1.0,
                    w11=1.0, w02=1.0)
CASES = {
    "plate, point force on and off": (PLATE, sd.Point(0.4, 0.3, (0, 0, -1),
                                                      profile=sd.Step(0.0, 2.0)), 1e-4),
    "light damping, uniform step": (sd.Material(mass=1.0, damping=0.05, w10=10.0, w01=10.0,
                                                w20=1.0, w11=1.0, w02=1.0),
                                    sd.Uniform((0, 0, -1), profile=sd.Step(0.0)), 1e-2),
    "heavy damping, late point force": (sd.Material(mass=1.0, damping=5.0, rayleigh=1e-3,
                                                    w10=10.0, w01=10.0, w20=1.0, w11=1.0,
                                                    w02=1.0),
                                        sd.Point(0.6, 0.5, (0, 0, 1), profile=sd.Step(0.5)),
                                        1e-6),
}


@pytest.mark.parametrize("case", CASES)
def test_automatic_mode_count_meets_the_requested_accuracy(case):
    material, load, tol = CASES[case]
    surf = sd.shapes.plane(cells=(22, 22))
    times = np.linspace(0.0, 4.0, 41)
    model = sd.Model(surf, material, boundary="clamped")
    sol = model.dynamic(load, 4.0, tolerance=tol, times=times)
    assert sol.truncation["modes"] < model.n_free and sol.truncation["bound"] <= tol
    full = sd.Model(surf, material, boundary="clamped").dynamic(load, 4.0, modes="all")
    rest = model.surface.control_points
    scale = max(np.abs(model.static(load, t=t).control_points() - rest).max()
                for t in (1.0, 3.9))
    error = np.abs(sol.control_points(times) - full.control_points(times)).max() / scale
    assert error <= tol


def test_decay_bound_dominates_the_free_response():
    """|P_11| against its bound on a grid across under-, critically and over-damped modes.

    Where the bound is tight (strongly over-damped, ``P_11 ≈ e^{-rτ}``) both sides are
    rounded separately: 1e-9 relative covers that, far below anything the bound is used for.
    """
    from splinedeform.solvers.analytic import propagator

    lam = np.logspace(-2, 6, 200)[:, None]
    for c in (np.zeros_like(lam), 0.3 + 1e-3 * lam, 2 * np.sqrt(lam), 50 + 0.1 * lam):
        tau = np.linspace(0, 5, 301)[None, :]
        p11 = propagator(lam, c, tau)[0]
        assert np.all(np.abs(p11) <= mode_count.decay_bound(lam, c, tau) * (1 + 1e-9) + 1e-15)
