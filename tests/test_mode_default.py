"""The default dynamic call: modes chosen for DEFAULT_TOLERANCE at any time asked.

``Model.dynamic(load, t_end)`` with nothing else keeps the largest control-point coordinate
error at most ``DEFAULT_TOLERANCE`` of the largest static displacement at every time asked,
including times chosen after the solve and times just after a load jump (where the basis'
bound misses and more modes are used). Reference: the same model with all modes (dense
``eigh``, exact to round-off, far below 1e-8). The nets are below the size where the
default starts its sparse path (``DENSE_BELOW``); it is lowered so that they exercise it.
"""

import numpy as np
import pytest

import splinedeform as sd
from splinedeform import modal_solve, threads
from splinedeform.solvers import mode_count

PLATE = sd.Material(mass=1.0, damping=0.8, rayleigh=5e-4, w10=10.0, w01=10.0, w20=1.0,
                    w11=1.0, w02=1.0)
HEAVY = sd.Material(mass=1.0, damping=5.0, rayleigh=1e-3, w10=10.0, w01=10.0, w20=1.0,
                    w11=1.0, w02=1.0)
CASES = {
    # plate with Rayleigh damping, point force on and off (the cost study's load)
    "plate, point force on and off": (PLATE, sd.Point(0.4, 0.3, (0, 0, -1),
                                                      profile=sd.Step(0.0, 2.0)),
                                      {"boundary": "clamped"}, 24),
    # heavy damping, a force switched on late, on a coarser net
    "heavy damping, late point force": (HEAVY, sd.Point(0.6, 0.5, (0, 0, 1),
                                                        profile=sd.Step(0.5)),
                                        {"boundary": "clamped"}, 20),
    # the intrinsic plate: a mass matrix without Kronecker structure (c_∞ from λ_min)
    "intrinsic plate, point force": (PLATE, sd.Point(0.4, 0.3, (0, 0, -1),
                                                     profile=sd.Step(0.0, 2.0)),
                                     {"boundary": "clamped", "physics": "intrinsic"}, 18),
}


@pytest.fixture(autouse=True)
def sparse_path_on_small_nets(monkeypatch):
    monkeypatch.setattr(modal_solve, "DENSE_BELOW", 256)


@pytest.mark.parametrize("case", CASES)
def test_the_default_call_meets_its_tolerance_at_any_time(case):
    """Times asked after the solve: the 201 it chose its modes for and random ones, then
    three just after a jump (1e-4 and 1e-3 later, where the basis' bound misses, so they
    come from a solution with modes chosen for them). Error ≤ DEFAULT_TOLERANCE, and not wastefully far
    below: the bound reached is within a factor 10 of it (one mode fewer would miss) and the
    measured error within 10⁴ (measured 2e2 to 1.1e3 below on these nets: the
    M-norm-to-largest-coordinate step of the bound is loose for a response spread over the
    net; 17 at 64²)."""
    material, load, options, cells = CASES[case]
    surf = sd.shapes.plane(cells=(cells, cells))
    model = sd.Model(surf, material, **options)
    sol = model.dynamic(load, 4.0)
    tol = modal_solve.DEFAULT_TOLERANCE
    assert not sol.basis.complete and sol.basis.kind == "sparse"
    assert tol / 10 <= sol.truncation["bound"] <= tol
    full = sd.Model(surf, material, **options).dynamic(load, 4.0, modes="all")
    assert full.basis.complete
    rest = surf.control_points
    scale = max(np.abs(model.static(load, t=t).control_points() - rest).max()
                for t in (1.0, 3.0))

    def error(times):
        return np.abs(sol.control_points(times) - full.control_points(times)).max() / scale

    jumps = np.array([t for t, _ in load.profile.jumps()])
    random = np.random.default_rng(3).uniform(0.0, 4.0, 60)
    # the bound is non-increasing between jumps: it holds at every time but those between
    # a jump and the next of the 201 times (0.02 apart) it was chosen for
    window = np.any((random[:, None] > jumps) & (random[:, None] < jumps + 0.02), axis=1)
    times = np.concatenate([np.linspace(0.0, 4.0, 201), random[~window]])
    assert not sol.accuracy.outside(times).any()
    assert tol * 1e-4 <= error(times) <= tol
    modes = sol.basis.size
    after = np.concatenate([jumps + 1e-4, jumps[:1] + 1e-3])
    assert sol.accuracy.outside(after).all()          # these times need more modes
    assert error(float(after[0])) <= tol              # one time asked alone, just after
    assert sol.basis.size == modes and sol.finer.basis.size > modes
    assert error(np.concatenate([times, after])) <= tol


def test_the_envelope_does_not_grow_with_time():
    """The bound between two times reads the earlier one: E(τ) must be non-increasing.
    Each bound of |P_11| is (module docstring of mode_count), so the supremum is; checked on
    a fine τ grid across damping regimes (1e-12 relative allows for rounding)."""
    tau = np.linspace(0.0, 3.0, 3001)[1:]
    for gamma, beta in ((0.0, 0.0), (0.05, 0.0), (0.8, 5e-4), (5.0, 1e-2)):
        E = mode_count.omitted_envelope(50.0, gamma, beta, tau)
        assert np.all(np.diff(E) <= 1e-12 * E[:-1])


@pytest.mark.parametrize("options", [{"boundary": "clamped"},
                                     {"boundary": "pinned", "mass_matrix": "lumped"},
                                     {"boundary": "clamped", "physics": "intrinsic"},
                                     {"boundary": "free", "fixed": "disc"}])
def test_the_pointwise_factor_bounds_every_coordinate_by_the_m_norm(options):
    """c_∞ against the exact max_p √((M_r⁻¹)_pp) (dense inverse of a small net): never
    below it, and the Kronecker, diagonal and λ_min routes within a factor 4 above it (the
    λ_min route: √(λ_max(M⁻¹)/max diag), measured 1.9-2.6 for cubic B-splines)."""
    surf = sd.shapes.plane(cells=(8, 8))
    if options.get("fixed") == "disc":
        g = surf.basis_u.greville()
        options = dict(options, fixed=(g[:, None] - 0.5) ** 2 + (g[None, :] - 0.5) ** 2 > 0.12)
    model = sd.Model(surf, PLATE, **options)
    M = model.matrices()[0].toarray()
    exact = np.sqrt(np.diag(np.linalg.inv(M)).max())
    c = modal_solve.pointwise_factor(model)
    assert exact * (1 - 1e-12) <= c <= 4 * exact     # 1e-12: the two inverses' rounding


def test_modes_all_and_bad_modes():
    surf = sd.shapes.plane(cells=(20, 20))
    model = sd.Model(surf, PLATE, boundary="clamped")
    load = CASES["plate, point force on and off"][1]
    assert model.dynamic(load, 4.0, modes="all").basis.complete
    with pytest.raises(sd.InputError, match="'all'"):
        model.dynamic(load, 4.0, modes="every")
    with pytest.raises(sd.InputError, match="without tolerance"):
        model.dynamic(load, 4.0, modes="all", tolerance=1e-6)


def test_problems_outside_the_bound_take_all_modes():
    """A harmonic load and an initial velocity are outside the bound: all modes, silently."""
    surf = sd.shapes.plane(cells=(20, 20))
    model = sd.Model(surf, PLATE, boundary="clamped")
    harmonic = sd.Point(0.4, 0.3, (0, 0, -1), profile=sd.Harmonic(3.0))
    assert model.dynamic(harmonic, 1.0).basis.complete
    v0 = np.zeros(surf.shape + (3,))
    v0[5, 5, 2] = 1.0
    assert model.dynamic(None, 1.0, initial_velocity=v0).basis.complete


def test_the_library_sets_its_blas_threads_and_the_user_overrides(monkeypatch):
    """Inside a library call BLAS runs with 1 thread, or SPLINEDEFORM_THREADS / set_threads;
    'blas' leaves BLAS's own setting; bad values are named."""
    threadpoolctl = pytest.importorskip("threadpoolctl")

    def blas_threads():
        return {i["num_threads"] for i in threadpoolctl.threadpool_info()
                if i["user_api"] == "blas"}

    outside = blas_threads()
    monkeypatch.delenv(threads.ENVIRONMENT, raising=False)
    with threads.library_threads():
        assert blas_threads() == {1}
    assert blas_threads() == outside
    monkeypatch.setenv(threads.ENVIRONMENT, "2")
    with threads.library_threads():
        assert blas_threads() == {2}
    monkeypatch.setenv(threads.ENVIRONMENT, "blas")
    with threads.library_threads():
        assert blas_threads() == outside
    threads.set_threads(1)
    try:
        with threads.library_threads():
            assert blas_threads() == {1}
    finally:
        threads.set_threads(None)
    monkeypatch.setenv(threads.ENVIRONMENT, "many")
    with pytest.raises(sd.InputError, match="SPLINEDEFORM_THREADS"):
        with threads.library_threads():
            pass
    with pytest.raises(sd.InputError, match="threads"):
        threads.set_threads(0)


def test_a_short_horizon_is_measured_against_its_own_largest_displacement():
    """t_end = 0.002, long before the plate reaches its static deflection (it reaches 7 %
    of it): the tolerance is relative to the largest displacement on [0, t_end], not to
    the static one. (So close after the jump the bound needs more than half the modes, and
    the default takes all of them.)"""
    material, load, options, cells = CASES["plate, point force on and off"]
    surf = sd.shapes.plane(cells=(cells, cells))
    sol = sd.Model(surf, material, **options).dynamic(load, 0.002)
    full = sd.Model(surf, material, **options).dynamic(load, 0.002, modes="all")
    times = np.linspace(0.0, 0.002, 101)
    rest = surf.control_points
    reference = full.control_points(times)
    largest = np.abs(reference - rest).max()
    static = np.abs(sd.Model(surf, material, **options).static(load, t=0.001)
                    .control_points() - rest).max()
    assert largest < 0.5 * static                     # the case: the motion stays below
    error = np.abs(sol.control_points(times) - reference).max() / largest
    assert error <= modal_solve.DEFAULT_TOLERANCE


def test_times_the_net_cannot_serve_are_warned_of_not_silently_missed(monkeypatch):
    """A time 1e-4 after a jump needs all modes with the static correction alone (the
    transient correction taken out of play: no count taken or estimated with it); with the
    complete eigen-solution out of reach (the dense limit lowered below the net) the
    solution says so (a warning and truncation["met"] False) and gives the computed modes'
    answer with its bound."""
    from splinedeform.solvers import modal_basis, mode_select

    material, load, options, cells = CASES["plate, point force on and off"]
    monkeypatch.setattr(modal_basis, "DENSE_MAX", 300)
    monkeypatch.setattr(mode_select, "over_damped_from", lambda gamma, beta: np.inf)
    monkeypatch.setattr(mode_select, "transient_count", lambda *args: None)
    monkeypatch.setattr(mode_select, "transient_grown", lambda *args: np.inf)
    surf = sd.shapes.plane(cells=(cells, cells))
    sol = sd.Model(surf, material, **options).dynamic(load, 4.0)
    assert sol.truncation["bound"] <= modal_solve.DEFAULT_TOLERANCE
    with pytest.warns(UserWarning, match="not met"):
        net = sol.control_points(2.0 + 1e-4)
    assert np.all(np.isfinite(net))
    assert sol.finer.truncation["met"] is False
    assert sol.finer.truncation["bound"] > modal_solve.DEFAULT_TOLERANCE


def test_a_time_just_after_a_jump_is_met_by_the_transient_correction(monkeypatch):
    """The same time 1e-4 after the switch-off, with the over-damped omitted modes' transient
    followed (solvers/transient_correction.py): no warning, fewer modes than the net has,
    within the default tolerance of all modes."""
    import warnings

    from splinedeform.solvers import modal_basis

    monkeypatch.setattr(modal_basis, "DENSE_MAX", 300)
    material, load, options, cells = CASES["plate, point force on and off"]
    surf = sd.shapes.plane(cells=(cells, cells))
    sol = sd.Model(surf, material, **options).dynamic(load, 4.0)
    full = sd.Model(surf, material, **options).dynamic(load, 4.0, modes="all")
    times = np.array([2.0 + 1e-4, 2.0 + 1e-3])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        net = sol.control_points(times)
    served = sol.finer if sol.finer is not None else sol
    assert served.truncation["modes"] < served.truncation["n_free"]
    rest = surf.control_points
    reference = full.control_points(times)
    largest = np.abs(full.control_points(np.linspace(0.0, 4.0, 201)) - rest).max()
    # the default: largest coordinate error <= 1e-8 of the largest displacement
    assert np.abs(net - reference).max() / largest <= modal_solve.DEFAULT_TOLERANCE


def test_frames_near_a_jump_are_met_with_fewer_modes_than_the_over_damped_range():
    """The cost study's frames (200 on [0, t_end], the first t_end/398 after the
    switch-off) on the 24² plate: one basis serves them all (chosen also half a spacing
    after each jump), its count below the first over-damped mode (the transient
    correction of under-damped omitted modes), and every frame within DEFAULT_TOLERANCE
    of all modes (dense eigh, exact to round-off) relative to the largest displacement."""
    from splinedeform.solvers.transient_correction import over_damped_from

    material, load, options, cells = CASES["plate, point force on and off"]
    surf = sd.shapes.plane(cells=(cells, cells))
    sol = sd.Model(surf, material, **options).dynamic(load, 4.0)
    frames = np.linspace(0.0, 4.0, 200)
    net = sol.control_points(frames)
    assert sol.finer is None                           # no second basis for the frames
    assert sol.truncation["correction_degree"] > 0
    # the first omitted mode is under-damped (λ_{m+1} < λ_o, here by a factor of 4 or more)
    assert sol.truncation["omega_first_omitted"] ** 2 < 0.25 * over_damped_from(0.8, 5e-4)
    full = sd.Model(surf, material, **options).dynamic(load, 4.0, modes="all")
    reference = full.control_points(frames)
    rest = surf.control_points
    error = np.abs(net - reference).max() / np.abs(reference - rest).max()
    assert error <= modal_solve.DEFAULT_TOLERANCE


def test_default_times_add_half_a_spacing_after_each_jump():
    """201 evenly spaced times and t_j + Δ/2 after each jump inside [0, t_end]; a jump at
    t_end adds nothing (times compared to 1e-12 of t_end: sums of floats)."""
    times = modal_solve.default_times(4.0, [0.0, 2.0, 4.0])
    step = 4.0 / (modal_solve.DEFAULT_TIMES - 1)
    assert times.size == modal_solve.DEFAULT_TIMES + 2
    extra = np.setdiff1d(times, np.linspace(0.0, 4.0, modal_solve.DEFAULT_TIMES))
    np.testing.assert_allclose(extra, [0.5 * step, 2.0 + 0.5 * step], rtol=0, atol=1e-12 * 4)


def test_the_largest_displacement_bound_is_below_the_largest_displacement():
    """_largest_below (the bound evaluated only at the times that can still decide
    max_t |d(t)| − bound(t)·S) is a lower bound of the largest displacement of all modes
    (dense eigh) on its times, and within 5 % of it on this net (measured 1.5 %: the
    largest displacement lies near, not at, the largest static one's coordinate; 1e-12 of
    S allowed for rounding)."""
    import scipy.sparse as sp

    from splinedeform.loads import as_load
    from splinedeform.solvers import mode_select
    from splinedeform.solvers.forcing import ReducedForcing

    material, load, options, cells = CASES["plate, point force on and off"]
    surf = sd.shapes.plane(cells=(cells, cells))
    model = sd.Model(surf, material, **options)
    M, _, K = model.matrices()
    jumps = ReducedForcing(model.reduction, as_load(load)).modal_terms(
        sp.identity(model.n_free, format="csr"), 4.0, 400)[0]
    times = np.linspace(0.0, 4.0, 301)
    basis, correction, report = mode_select.automatic_basis(
        K, M, jumps, 0.8, 5e-4, times, 1e-8, pointwise=modal_solve.pointwise_factor(model))
    got = modal_solve._largest_below(basis, correction, report, jumps, 0.8, 5e-4, times)
    full = sd.Model(surf, material, **options).dynamic(load, 4.0, modes="all")
    largest = np.abs(full.control_points(times) - surf.control_points).max()
    assert got <= largest + 1e-12 * report["scale"]
    assert got >= 0.95 * largest
