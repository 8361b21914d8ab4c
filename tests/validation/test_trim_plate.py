"""Circular Kirchhoff plates as trimmed squares in WEB-splines against closed forms."""

import numpy as np
import pytest
import scipy.linalg as sl
import scipy.sparse.linalg as spl

from splinedeform.trim import CircleLoop, TrimDomain
from splinedeform.trim.plate import assemble_plate
from splinedeform.trim.weight import DiscWeight, RvachevWeight

A = 0.4                                       # plate radius; centre (0.5, 0.5) of [0, 1]²
CENTRE = np.array([[0.5, 0.5]])


def _centre_deflection(plate):
    coefficients = spl.spsolve(plate.stiffness.tocsc(), plate.load)
    return plate.deflection(coefficients, CENTRE)[0]


@pytest.mark.parametrize("poisson", [0.0, 0.3])
def test_clamped_plate_centre_deflection(poisson):
    # w = q a⁴/(64 D) (1 - r²/a²)² (Timoshenko & Woinowsky-Krieger §62); basis w² B_i with
    # w = 1 - r²/a² holds d = ∂_n d = 0 and spans the solution: 0.1 % is the task's bar
    plate = assemble_plate(TrimDomain(CircleLoop((0.5, 0.5), A)), 4, 3,
                           DiscWeight((0.5, 0.5), A, 2), poisson=poisson)
    assert abs(_centre_deflection(plate) / (A ** 4 / 64) - 1) < 1e-3


@pytest.mark.parametrize("poisson", [0.0, 0.3])
def test_simply_supported_plate_centre_deflection(poisson):
    # w_0 = (5 + ν) q a⁴ / (64 (1 + ν) D) (Timoshenko & Woinowsky-Krieger §63); basis w B_i
    # holds d = 0, the zero moment is natural; 0.1 % is the task's bar
    plate = assemble_plate(TrimDomain(CircleLoop((0.5, 0.5), A)), 4, 3,
                           DiscWeight((0.5, 0.5), A, 1), poisson=poisson)
    exact = (5 + poisson) * A ** 4 / (64 * (1 + poisson))
    assert abs(_centre_deflection(plate) / exact - 1) < 1e-3


def test_clamped_plate_frequencies_against_bessel_roots():
    # ω a² sqrt(ρh/D) = λ², λ² = 10.2158, 21.2604 (twice), 34.8770 (Leissa, NASA SP-160,
    # table 2.1); 6 × 6 cells of quartic WEB-splines reach ~1e-4, the bar is 1e-3
    plate = assemble_plate(TrimDomain(CircleLoop((0.5, 0.5), A)), 6, 4,
                           DiscWeight((0.5, 0.5), A, 2))
    eigenvalues = sl.eigh(plate.stiffness.toarray(), plate.mass.toarray(), eigvals_only=True)
    lam2 = np.sqrt(eigenvalues[:5]) * A ** 2
    expected = np.array([10.2158, 21.2604, 21.2604, 34.8770, 34.8770])
    assert np.max(np.abs(lam2 / expected - 1)) < 1e-3


def _annulus_deflection(r, a, b):
    """Clamped annulus ``b < r < a`` under ``q = D = 1``: ``w = r⁴/64 + C1 + C2 r² + C3 ln r
    + C4 r² ln r`` (the axisymmetric solutions of ``Δ²w = 1``) with ``w = w' = 0`` at
    both radii, the constants from that 4 × 4 system."""
    rows, rhs = [], []
    for x in (a, b):
        rows += [[1, x * x, np.log(x), x * x * np.log(x)], [0, 2 * x, 1 / x, 2 * x * np.log(x) + x]]
        rhs += [-x ** 4 / 64, -x ** 3 / 16]
    c = np.linalg.solve(np.array(rows), rhs)
    return r ** 4 / 64 + c[0] + c[1] * r * r + c[2] * np.log(r) + c[3] * r * r * np.log(r)


def test_clamped_annulus_with_the_rvachev_weight():
    # the two circles' R-conjunction is smooth (they never meet); w² B_i on 12 × 12 cubic
    # cells: measured 2e-5 at mid-radius (1e-3 on 8 or 10 cells, 2e-4 on 16); bar 0.1 %
    a, b = A, 0.15
    annulus = TrimDomain(CircleLoop((0.5, 0.5), a), (CircleLoop((0.5, 0.5), b),))
    plate = assemble_plate(annulus, 12, 3, RvachevWeight(annulus, 2))
    coefficients = spl.spsolve(plate.stiffness.tocsc(), plate.load)
    r = 0.5 * (a + b)
    w = plate.deflection(coefficients, np.array([[0.5 + r, 0.5], [0.5, 0.5 - r]]))
    assert np.max(np.abs(w / _annulus_deflection(r, a, b) - 1)) < 1e-3
