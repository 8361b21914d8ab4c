"""The plate energy on NURBS patches whose weights are not a product (element by element)."""

import numpy as np
from scipy.interpolate import BSpline

import splinedeform as sd
from splinedeform.knots import KnotVectorBasis, RationalBasis
from splinedeform.physics import rational_plate

PLATE = sd.Material(mass=1.7, w10=1.0, w01=0.5, w20=0.1, w11=0.07, w02=0.2)
KNOTS_U = np.array([0, 0, 0, 0.4, 1, 1, 1.0])
KNOTS_V = np.array([0, 0, 0, 0, 0.3, 0.7, 1.2, 1.2, 1.2, 1.2])


def general_weights() -> np.ndarray:
    rng = np.random.default_rng(7)
    w = rng.uniform(0.5, 2.0, (4, 6))
    u, s, vt = np.linalg.svd(w)
    assert s[1] > 0.1 * s[0]          # far from a product a_i b_j
    return w


def _energy_by_scipy(d: np.ndarray, w: np.ndarray, points: int = 24
                     ) -> tuple[float, float]:
    """½ ∫∫ (plate energy density) and ∫∫ μ d² of the field ``d = Σ w d N N / Σ w N N``,
    evaluated by scipy's BSpline and integrated with ``points`` Gauss points per span."""
    x, a = np.polynomial.legendre.leggauss(points)

    def rule(knots):
        breaks = np.unique(knots)
        left, h = breaks[:-1, None], np.diff(breaks)[:, None]
        return (left + 0.5 * h * (x + 1)).ravel(), (0.5 * h * a).ravel()

    (u, au), (v, av) = rule(KNOTS_U), rule(KNOTS_V)
    Bu = [BSpline(KNOTS_U, np.eye(4), 2)(u, nu=p) for p in range(3)]
    Bv = [BSpline(KNOTS_V, np.eye(6), 3)(v, nu=p) for p in range(3)]
    f = {(p, q): Bu[p] @ (w * d) @ Bv[q].T for p in range(3) for q in range(3 - p)}
    W = {(p, q): Bu[p] @ w @ Bv[q].T for p in range(3) for q in range(3 - p)}
    z = f[0, 0] / W[0, 0]
    zu = (f[1, 0] - z * W[1, 0]) / W[0, 0]
    zv = (f[0, 1] - z * W[0, 1]) / W[0, 0]
    zuu = (f[2, 0] - 2 * zu * W[1, 0] - z * W[2, 0]) / W[0, 0]
    zvv = (f[0, 2] - 2 * zv * W[0, 1] - z * W[0, 2]) / W[0, 0]
    zuv = (f[1, 1] - zu * W[0, 1] - zv * W[1, 0] - z * W[1, 1]) / W[0, 0]
    m = PLATE
    density = (m.w10 * zu**2 + m.w01 * zv**2 + m.w20 * zuu**2 + 2 * m.w11 * zuv**2
               + m.w02 * zvv**2)
    return 0.5 * au @ density @ av, m.mass * au @ (z**2) @ av


def test_general_weights_stiffness_against_an_independent_quadrature():
    w = general_weights()
    bu, bv = KnotVectorBasis(2, KNOTS_U), KnotVectorBasis(3, KNOTS_V)
    K, M = rational_plate.matrices(bu, bv, w, PLATE, points_per_cell=24)
    K0, _ = rational_plate.matrices(bu, bv, w, PLATE)       # the default rule, 14 x 16
    rng = np.random.default_rng(3)
    for _ in range(3):
        d = rng.normal(size=(4, 6)).ravel()
        energy, mass = _energy_by_scipy(d.reshape(4, 6), w, points=32)
        # the same integrals by two evaluators and two Gauss rules (24 and 32 points per
        # span of a rational integrand): measured 1e-13 relative, asserted to 1e-11
        assert abs(0.5 * d @ K @ d - energy) <= 1e-11 * energy
        assert abs(d @ M @ d - mass) <= 1e-11 * mass
        # the default rule on weights varying by 4 between neighbours: measured 1e-8
        assert abs(0.5 * d @ K0 @ d - energy) <= 1e-7 * energy


def test_mass_of_the_rational_basis_sums_to_the_domain_area():
    K, M = rational_plate.matrices(KnotVectorBasis(2, KNOTS_U), KnotVectorBasis(3, KNOTS_V),
                                   general_weights(), PLATE)
    # Σ_k R_k = 1: Σ_kl M_kl = μ L_u L_v; a constant field has no strain energy
    # (round-off of sums of O(1) numbers)
    assert abs(M.sum() - PLATE.mass * 1.0 * 1.2) <= 1e-12
    assert np.abs(K @ np.ones(K.shape[0])).max() <= 1e-11 * np.abs(K.data).max()


def test_product_weights_give_the_kronecker_matrices():
    a, b = np.array([1.0, 0.7, 1.3, 1.0]), np.array([1.0, 0.8, 1.1, 0.9, 1.2, 1.0])
    bu, bv = KnotVectorBasis(2, KNOTS_U), KnotVectorBasis(3, KNOTS_V)
    grid = np.stack([*np.meshgrid(bu.greville(), bv.greville(), indexing="ij")]
                    + [np.zeros((4, 6))], -1)
    surface = sd.Surface(grid, RationalBasis(bu, a), RationalBasis(bv, b))
    model = sd.Model(surface, PLATE)
    K, M = rational_plate.matrices(bu, bv, np.outer(a, b), PLATE)
    # the same integrals, 1-D Gram matrices of R_i(u), R_j(v) (14 and 16 points) against
    # the 2-D rule: quadrature error of rational integrands, measured 1e-15, asserted 1e-11
    for ours, kron in ((K, model.K_full), (M, model.M_full)):
        assert np.abs((ours - kron).toarray()).max() <= 1e-11 * np.abs(kron.data).max()
