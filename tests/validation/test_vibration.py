"""Free vibration of a simply supported square plate and a fixed square membrane.

References
----------
* Simply supported Kirchhoff plate of side a: ω_mn a² √(μ/D) = π² (m² + n²), i.e.
  2π², 5π², 5π², 8π² for the lowest four (Leissa, *Vibration of Plates*, NASA SP-160, 1969,
  eq. 4.23).
* Membrane with fixed edges: ω_mn = (π/a) √(T/μ) √(m² + n²).
"""

import numpy as np
import pytest

import splinedeform as sd

EXACT_PLATE = np.pi**2 * np.array([2, 5, 5, 8])


def plate_frequencies(knots, cells=12, mass_matrix="consistent", a=1.5, D=0.8, mu=2.0):
    surf = sd.shapes.plane(size=(a, a), cells=(cells, cells), degree=3, knots=knots)
    model = sd.Model(surf, sd.Material(mass=mu, w20=D, w11=D, w02=D), boundary="pinned",
                     mass_matrix=mass_matrix)
    return model.frequencies(4) * a**2 * np.sqrt(mu / D)


@pytest.mark.parametrize("knots", ["open", "uniform"])
def test_simply_supported_plate_frequencies(knots):
    assert plate_frequencies(knots) == pytest.approx(EXACT_PLATE, rel=1e-3)


def test_membrane_frequencies():
    T, mu, a = 3.0, 1.5, 2.0
    surf = sd.shapes.plane(size=(a, a), cells=(12, 12), degree=3, knots="uniform")
    model = sd.Model(surf, sd.Material(mass=mu, w10=T, w01=T), boundary="pinned")
    exact = np.pi / a * np.sqrt(T / mu) * np.sqrt([2, 5, 5, 8, 10, 10])
    assert model.frequencies(6) == pytest.approx(exact, rel=1e-4)


def test_consistent_mass_converges_from_above_and_lumped_is_less_accurate():
    """Consistent mass gives upper bounds (Rayleigh–Ritz); row-sum lumping is cheaper but
    its error is larger on the same net (the docs quote these numbers)."""
    err = {}
    for kind in ("consistent", "lumped"):
        for cells in (8, 16):
            omega = plate_frequencies("open", cells, kind)
            if kind == "consistent":
                assert np.all(omega >= EXACT_PLATE * (1 - 1e-12))
            err[kind, cells] = np.abs(omega / EXACT_PLATE - 1).max()
    # consistent mass: order ~4 (measured 1.9e-4 -> 1.1e-5); lumped: order ~2 (0.15 -> 0.043)
    assert np.log2(err["consistent", 8] / err["consistent", 16]) > 3.5
    assert 1.5 < np.log2(err["lumped", 8] / err["lumped", 16]) < 2.5
    assert err["lumped", 16] > 100 * err["consistent", 16]
