"""All modes by the Kronecker reduction to standard form, against LAPACK's generalised ``eigh``.

The reference is ``scipy.linalg.eigh(K_r, M_r)`` (``sygvd``) of the assembled reduced
matrices; both are backward stable, so eigenvalues agree to a small multiple of
``ε λ_max κ(G0)`` (κ(G0) ≈ 20 for cubics): 1e-11 λ_max is a margin of ~100.
"""

import numpy as np
import pytest
import scipy.linalg as sla

import splinedeform as sd
from splinedeform import spectrum
from splinedeform.solvers import kronecker_eigen as ke

MATERIAL = sd.Material(mass=1.7, damping=0.3, rayleigh=1e-3, w10=2.0, w01=1.0, w20=0.5,
                       w11=0.4, w02=0.3)
LOAD = (sd.Point(0.3, 0.6, (0.0, 0.0, -1.0), profile=sd.Step(0.1, 0.5))
        + sd.Uniform((0.0, 0.0, 0.2), profile=sd.Harmonic(7.0, 0.3)))
CASES = {
    "open clamped": ({"knots": "open"}, "clamped", None),
    "uniform mixed": ({"knots": "uniform"}, {"u0": "clamped", "u1": "pinned", "v1": "clamped"},
                      None),
    "rectangle of free points": ({"knots": "open"}, "free", (slice(2, 7), slice(3, 9))),
}


def build(case):
    kwargs, boundary, region = CASES[case]
    surf = sd.shapes.plane(size=(1.0, 1.3), cells=(7, 9), **kwargs)
    fixed = None
    if region is not None:
        fixed = np.ones(surf.shape, bool)
        fixed[region] = False
    return sd.Model(surf, MATERIAL, boundary=boundary, fixed=fixed)


@pytest.mark.parametrize("case", CASES)
def test_kronecker_reduction_matches_generalised_eigh(case):
    model = build(case)
    assert spectrum.kronecker_reason(model) is None
    M, _, K = model.matrices()
    lam, phi = ke.eigenpairs(model.kronecker_factors())
    ref = sla.eigh(K.toarray(), M.toarray(), eigvals_only=True)
    assert np.abs(lam - ref).max() <= 1e-11 * ref.max()
    assert np.abs(phi.T @ (M @ phi) - np.eye(lam.size)).max() <= 1e-11
    assert np.abs(phi.T @ (K @ phi) - np.diag(lam)).max() <= 1e-11 * ref.max()


@pytest.mark.parametrize("case", CASES)
def test_dynamic_frames_agree_with_the_generalised_path(case, monkeypatch):
    """Frames through both eigen-solutions agree to 1e-10 of the peak displacement.

    Every modal response is a smooth function of (λ, φ), both accurate to ~1e-13 relative,
    so 1e-10 is a wide margin; it is no bit-for-bit comparison.
    """
    times = np.linspace(0.0, 1.0, 9)
    fast = build(case).dynamic(LOAD, 1.0)
    assert fast.basis.kind == "dense"
    monkeypatch.setattr(spectrum, "kronecker_reason", lambda model: "forced off")
    slow = build(case).dynamic(LOAD, 1.0)
    a, b = fast.control_points(times), slow.control_points(times)
    rest = build(case).surface.control_points
    assert np.abs(a - b).max() <= 1e-10 * np.abs(b - rest).max()


def test_only_the_loaded_coordinate_moves():
    model = build("open clamped")
    sol = model.dynamic(LOAD, 1.0)
    assert list(sol.response.active) == [2]
    d = sol.control_points(np.linspace(0, 1, 5)) - model.surface.control_points
    assert np.all(d[..., :2] == 0.0)            # x and y have no load and no initial state
    assert np.abs(d[..., 2]).max() > 0
    v0 = np.zeros(model.surface.shape + (3,))
    v0[4, 5, 0] = 1.0
    moved = model.dynamic(LOAD, 1.0, initial_velocity=v0)
    assert list(moved.response.active) == [0, 2]


def test_few_frequencies_by_sparse_lanczos_agree_with_all_modes():
    """frequencies(5) of a 24×24 quartic plate with twist (no separable factors) from
    sparse shift-invert Lanczos, against the lowest 5 of all modes: 1e-9 relative (Lanczos
    converges to its default tolerance ε·|λ| on these well-separated modes)."""
    surf = sd.shapes.plane(cells=(24, 24), degree=4)
    material = sd.Material(w10=1.0, w01=1.0, w20=1.0, w11=1.0, w02=1.0)
    few = sd.Model(surf, material, boundary="clamped")
    omega = few.frequencies(5)
    assert [key[0] for key in few._bases] == ["sparse"]
    full = sd.Model(surf, material, boundary="clamped")
    lam_all = full.modal_basis().lam
    assert np.abs(omega - np.sqrt(lam_all[:5])).max() <= 1e-9 * omega.max()
