"""Static deflections of square membranes and Kirchhoff plates against classical solutions.

References
----------
* Membrane (−T Δw = q, w = 0 on the edges of the square of side a): centre deflection
  w = 0.0736713 q a² / T, from the double sine series
  w = (16 q a²/(π⁴ T)) Σ_{m,n odd} (−1)^{(m+n)/2−1} / (m n (m² + n²)).
* Kirchhoff plate (D Δ²w = q): clamped 0.0012653 q a⁴ / D (Timoshenko & Woinowsky-Krieger,
  *Theory of Plates and Shells*, Table 35, tabulated there as 0.00126), simply supported
  0.0040624 q a⁴ / D (Navier series, same book Table 8, tabulated as 0.00406):
  w = (16 q a⁴/(π⁶ D)) Σ_{m,n odd} (−1)^{(m+n)/2−1} / (m n (m² + n²)²).
Simply supported and membrane edges use ``boundary="pinned"`` (w = 0; the natural condition
w_nn = 0 then holds weakly since the energy w20|w_uu|² + 2w11|w_uv|² + w02|w_vv|² has no
boundary term to enforce). Both knot layouts give the same spline space on [0, a], so both
must pass.
"""

import numpy as np
import pytest

import splinedeform as sd


def navier_series(power: int, terms: int = 2001) -> float:
    """Σ_{m,n odd} (−1)^{(m+n)/2−1} / (m n (m² + n²)^power) (centre value kernel)."""
    m = np.arange(1, terms, 2, dtype=float)
    M, N = np.meshgrid(m, m, indexing="ij")
    sign = (-1.0) ** ((M + N) / 2 - 1)
    return float(np.sum(sign / (M * N * (M**2 + N**2) ** power)))


MEMBRANE = 16 / np.pi**4 * navier_series(1)
PLATE_SS = 16 / np.pi**6 * navier_series(2, 401)
PLATE_CLAMPED = 0.00126532  # Timoshenko & Woinowsky-Krieger; more digits from Taylor & Govindjee (2004): 0.001265319


def test_series_reproduce_the_tabulated_constants():
    assert abs(MEMBRANE - 0.0736713) < 5e-7
    assert abs(PLATE_SS - 0.0040624) < 5e-8


def centre_deflection(knots, cells, material, boundary, a=2.0, q=3.0):
    surf = sd.shapes.plane(size=(a, a), cells=(cells, cells), degree=3, knots=knots)
    model = sd.Model(surf, material, boundary=boundary)
    return model.static(sd.Uniform((0, 0, q))).displacement(a / 2, a / 2)[2]


@pytest.mark.parametrize("knots", ["open", "uniform"])
def test_membrane_centre_deflection(knots):
    T, a, q = 2.5, 2.0, 3.0
    w = centre_deflection(knots, 16, sd.Material(w10=T, w01=T), "pinned", a, q)
    assert w == pytest.approx(0.0736713 * q * a**2 / T, rel=1e-3)
    assert w == pytest.approx(MEMBRANE * q * a**2 / T, rel=1e-5)


@pytest.mark.parametrize("knots", ["open", "uniform"])
@pytest.mark.parametrize("boundary, reference", [("clamped", 0.0012653), ("pinned", 0.0040624)])
def test_kirchhoff_plate_centre_deflection(knots, boundary, reference):
    D, a, q = 0.7, 2.0, 3.0
    w = centre_deflection(knots, 16, sd.Material(w20=D, w11=D, w02=D), boundary, a, q)
    assert w == pytest.approx(reference * q * a**4 / D, rel=1e-3)


def test_plate_deflection_converges_at_the_expected_rate():
    """Simply supported plate with cubic B-splines: centre error ~ h^4 (measured order 4 ± 0.5)."""
    D = 1.0
    cells = np.array([2, 4, 8, 16])
    errors = np.array([abs(centre_deflection("open", m, sd.Material(w20=D, w11=D, w02=D),
                                              "pinned", 1.0, 1.0) - PLATE_SS) for m in cells])
    rates = np.log2(errors[:-1] / errors[1:])
    assert np.all(rates[1:] > 3.5) and np.all(rates[1:] < 4.5), rates
    assert errors[-1] / PLATE_SS < 1e-5


def test_membrane_deflection_converges():
    """Membrane with cubics: the load is smooth but the corners limit the order; error falls
    at least quadratically and the finest net is within 1e-5."""
    cells = np.array([4, 8, 16, 32])
    errors = np.array([abs(centre_deflection("uniform", m, sd.Material(w10=1, w01=1), "pinned",
                                              1.0, 1.0) - MEMBRANE) for m in cells])
    rates = np.log2(errors[:-1] / errors[1:])
    assert np.all(rates > 2.0), rates
    assert errors[-1] / MEMBRANE < 1e-5
