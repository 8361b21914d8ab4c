"""The fewest modes for a requested accuracy (solvers/mode_select.py).

The error is measured as the bound states it: the largest control-point coordinate
difference, relative to the largest static displacement ``max_t ‖K⁻¹F(t)‖_∞``.
References: the same model with all modes (dense, exact to round-off) on a small net; a
Radau IIA-7 run with many steps per frame on a medium net, an independent computation
whose own error (order 13) is far below the tolerances compared.
"""

import numpy as np
import pytest

import splinedeform as sd
from splinedeform.solvers import mode_count, mode_select

@pytest.fixture(autouse=True)
def sparse_path_on_small_nets(monkeypatch):
    """These nets (361 to 841 free coordinates) are below the size where the automatic
    mode count starts its sparse path; lowered, they exercise it in a fraction of the time."""
    from splinedeform import modal_solve
    monkeypatch.setattr(modal_solve, "DENSE_BELOW", 256)


PLATE = sd.Material(mass=1.0, damping=0.8, rayleigh=5e-4, w10=10.0, w01=10.0, w20=1.0,
                    w11=1.0, w02=1.0)
LOAD = sd.Point(0.4, 0.3, (0, 0, -1), profile=sd.Step(0.0, 2.0))


def relative_errors(model, a, b, times, load):
    """Per frame: the largest control-point coordinate difference over the largest static
    displacement (the bound's measure; the load is on over [0, 2))."""
    rest = model.surface.control_points
    scale = np.abs(model.static(load, t=1.0).control_points() - rest).max()
    return np.abs(np.asarray(a) - np.asarray(b)).reshape(times.size, -1).max(axis=1) / scale


@pytest.mark.parametrize("t", [0.05, 1.3, 2.02, 3.7])
def test_one_state_meets_the_tolerance_with_the_fewest_modes_for_its_time(t):
    """One time right after a jump (0.05, 2.02) or long after (1.3, 3.7). Long after a jump
    one state needs no more modes than 41 frames (0.1 apart) do; right after it, more."""
    surf = sd.shapes.plane(cells=(20, 20))
    tol = 1e-6
    model = sd.Model(surf, PLATE, boundary="clamped")
    one = model.dynamic(LOAD, 4.0, tolerance=tol, times=[t])
    full = sd.Model(surf, PLATE, boundary="clamped").dynamic(LOAD, 4.0, modes="all")
    times = np.array([t])
    err = relative_errors(model, one.control_points(times), full.control_points(times),
                          times, LOAD)
    assert one.truncation["bound"] <= tol
    assert err.max() <= tol
    many = sd.Model(surf, PLATE, boundary="clamped").dynamic(
        LOAD, 4.0, tolerance=tol, times=np.linspace(0.0, 4.0, 41))
    if t in (1.3, 3.7):
        assert one.truncation["modes"] <= many.truncation["modes"]


def test_frames_of_a_medium_net_agree_with_a_fine_radau_solution():
    """30² net (841 free coordinates; no dense solution used), 21 frames, 1e-6. Radau IIA-7
    with 24 steps per frame is within 1e-10 of the all-modes solution on a 36² net."""
    surf = sd.shapes.plane(cells=(30, 30))
    times = np.linspace(0.0, 4.0, 21)
    tol = 1e-6
    model = sd.Model(surf, PLATE, boundary="clamped")
    sol = model.dynamic(LOAD, 4.0, tolerance=tol, times=times)
    assert sol.truncation["modes"] < model.n_free // 2 and sol.basis.kind == "sparse"
    radau = sd.Model(surf, PLATE, boundary="clamped").dynamic(
        LOAD, 4.0, method="radau7", times=times, substeps=24)
    err = relative_errors(model, sol.control_points(times), radau.control_points(times),
                          times, LOAD)
    assert err.max() <= tol


def test_the_envelope_table_dominates_the_envelope():
    """Row i of the table (a running maximum from the top of its grid) against
    mode_count.omitted_envelope from grid[i] upwards (its own grid: 3000 values over 12
    decades). Both sample the same smooth supremum at 250 values per decade on grids offset
    from each other, so they may differ by the bound's change between neighbouring samples
    (measured: 4e-8 relative); 1e-6 relative allows that. The table's rows decrease."""
    tau = np.array([1e-3, 0.02, 0.3, 2.0])
    grid, E = mode_select.envelope_table(40.0, 0.8, 5e-4, tau)
    for i in (0, 700, 1500, 2400):
        direct = mode_count.omitted_envelope(grid[i], 0.8, 5e-4, tau)
        assert np.all(E[i] >= direct * (1 - 1e-6))
    assert np.all(np.diff(E, axis=0) <= 0)


def test_a_further_load_case_reuses_the_eigen_solution():
    """A second load on a solved model: the same answer as on a fresh model (two Krylov
    spaces with converged pairs: 1e-9 of the static scale covers their 1e-10 residuals),
    and no new solves beyond its statics when it needs no more modes. 21 frames: more than
    ONE_OFF_TIMES, so the model's own (random-start) space is made and kept."""
    surf = sd.shapes.plane(cells=(20, 20))
    times = np.linspace(1.3, 3.1, 21)
    second = sd.Point(0.7, 0.6, (0, 0, -2), profile=sd.Step(0.5))
    model = sd.Model(surf, PLATE, boundary="clamped")
    model.dynamic(LOAD, 4.0, tolerance=1e-6, times=times)
    from splinedeform import modal_solve
    solves = modal_solve._KRYLOV[model].solves
    again = model.dynamic(second, 4.0, tolerance=1e-6, times=times).control_points(times)
    fresh = sd.Model(surf, PLATE, boundary="clamped").dynamic(
        second, 4.0, tolerance=1e-6, times=times).control_points(times)
    rest = model.surface.control_points
    assert np.abs(again - fresh).max() <= 1e-9 * np.abs(fresh - rest).max()
    assert modal_solve._KRYLOV[model].solves == solves


def test_a_small_net_takes_all_modes_without_starting_the_sparse_path():
    """49 free coordinates (at most DENSE_BELOW): the tolerance is met exactly, by every mode."""
    from splinedeform import modal_solve

    surf = sd.shapes.plane(cells=(8, 8))
    model = sd.Model(surf, PLATE, boundary="clamped")
    assert model.n_free == 49 <= modal_solve.DENSE_BELOW
    times = np.linspace(0.0, 4.0, 11)
    sol = model.dynamic(LOAD, 4.0, tolerance=1e-6, times=times)
    assert sol.basis.complete and sol.basis.lam.size == 49
    assert sol.truncation["bound"] == 0.0 and model not in modal_solve._KRYLOV
    full = sd.Model(surf, PLATE, boundary="clamped").dynamic(LOAD, 4.0, modes="all")
    err = relative_errors(model, sol.control_points(times), full.control_points(times),
                          times, LOAD)
    assert err.max() <= 1e-12        # the same complete solution: round-off only
