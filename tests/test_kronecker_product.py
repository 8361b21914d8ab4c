"""The mass product through its Kronecker factors, and the one-vector Lanczos step.

``M_r = μ Ĝ0u ⊗ Ĝ0v`` on a tensor-product net: its product through the two 1-D factors is
compared with scipy's ``kron`` and with the assembled ``M_r`` (both exact up to rounding,
about 1e-16 of the largest entry). The Krylov space that uses it (and the one-vector step of
a load-started space) is compared with dense ``eigh`` of the same matrices.
"""

import numpy as np
import pytest
import scipy.linalg as sla
import scipy.sparse as sp

import splinedeform as sd
from splinedeform.spectrum import kronecker_mass
from splinedeform.solvers.kronecker_product import KroneckerProduct, checked
from splinedeform.solvers.sparse_eigen import BlockLanczos, factorise

PLATE = sd.Material(mass=2.5, damping=0.8, rayleigh=5e-4, w10=10.0, w01=10.0, w20=1.0,
                    w11=1.0, w02=1.0)


def test_the_product_equals_scipys_kron_for_vectors_and_blocks():
    """Random banded factors of different sizes and a scale: one vector and a block of 3,
    to 1e-14 of the largest entry (a few roundings of sums of at most 7 × 5 terms)."""
    rng = np.random.default_rng(1)
    A = sp.random(7, 7, density=0.6, random_state=rng) + sp.eye(7)
    B = sp.random(5, 5, density=0.6, random_state=rng) + sp.eye(5)
    product = KroneckerProduct(A, B, scale=1.7)
    K = 1.7 * sp.kron(A, B).toarray()
    for x in (rng.standard_normal(35), rng.standard_normal((35, 3))):
        reference = K @ x
        assert np.abs(product(x) - reference).max() <= 1e-14 * np.abs(reference).max()
        assert product(x).shape == x.shape


def test_a_models_mass_is_taken_through_its_factors_only_where_they_reproduce_it():
    """The clamped plate's ``M_r`` (μ = 2.5) is its factors' product to rounding; a free
    region that is no rectangle, and a lumped mass, are not such products, so no factors."""
    surface = sd.shapes.plane(cells=(8, 8))
    model = sd.Model(surface, PLATE, boundary="clamped")
    M, _, _ = model.matrices()
    product = kronecker_mass(model, M)
    assert product is not None
    x = np.random.default_rng(2).standard_normal(M.shape[0])
    assert np.abs(product(x) - M @ x).max() <= 1e-14 * np.abs(M @ x).max()
    g = surface.basis_u.greville()
    outside = (g[:, None] - 0.5) ** 2 + (g[None, :] - 0.5) ** 2 > 0.35**2
    region = sd.Model(surface, PLATE, boundary="free", fixed=outside)
    assert kronecker_mass(region, region.matrices()[0]) is None
    lumped = sd.Model(surface, PLATE, boundary="clamped", mass_matrix="lumped")
    assert kronecker_mass(lumped, lumped.matrices()[0]) is None
    # a product of other factors than the matrix's is refused by the check
    wrong = KroneckerProduct(sp.eye(surface.shape[0] - 4), sp.eye(surface.shape[1] - 4))
    assert checked(wrong, M) is None


@pytest.mark.parametrize("start", ["load", "random"])
def test_lanczos_with_the_factored_mass_finds_the_dense_spectrum(start):
    """Block Lanczos with the mass product through the factors: a space started from an
    off-centre force (blocks of one vector, the one-vector step) and a random block; the 10
    lowest eigenvalues equal dense ``eigh``'s to 1e-10 relative (converged Ritz pairs,
    residual 1e-10), the modes M-orthonormal to 1e-10."""
    model = sd.Model(sd.shapes.plane(cells=(14, 14)), PLATE, boundary="clamped")
    M, _, K = model.matrices()
    exact = sla.eigh(K.toarray(), M.toarray(), eigvals_only=True)
    lu = factorise(K)
    E = model.surface.evaluation_matrix(np.array([0.4]), np.array([0.3]))
    force = np.asarray((model.T.T @ E.T).todense())
    space = BlockLanczos(K, M, lu, start=lu.solve(force) if start == "load" else None,
                         mass_product=kronecker_mass(model, M))
    assert (space.b == 1) == (start == "load")
    found = space.lowest(9)
    assert np.allclose(found.lam, exact[:10], rtol=1e-10, atol=0)
    phi = found.phi
    assert np.abs(phi.T @ (M @ phi) - np.eye(phi.shape[1])).max() <= 1e-10
