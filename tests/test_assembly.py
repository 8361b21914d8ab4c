"""Kronecker assembly (assembly.py) against scipy's kron and the reduction T^T K T."""

import numpy as np
import pytest
import scipy.sparse as sp

import splinedeform as sd
from splinedeform.assembly import full_matrices, kronecker_sum, reduced_matrices

PLATE = sd.Material(mass=1.3, damping=0.8, rayleigh=5e-4, w10=10.0, w01=7.0, w20=1.0,
                    w11=0.5, w02=2.0)


@pytest.mark.parametrize("format", ["csr", "csc"])
def test_kronecker_sum_equals_the_sum_of_scipy_krons(format):
    """Different patterns per term (the union is taken), rectangular factors, both layouts."""
    rng = np.random.default_rng(0)
    terms = [(w, sp.random(5, 4, 0.5, random_state=rng), sp.random(3, 6, 0.4, random_state=rng))
             for w in (1.5, -2.0, 0.25)]
    expected = sum(w * sp.kron(A, B) for w, A, B in terms).toarray()
    K = kronecker_sum(terms, format=format)
    assert K.format == format and K.shape == (15, 24) and K.has_sorted_indices
    K.check_format(full_check=True)
    # sums of three products of O(1) numbers: a few roundings
    np.testing.assert_allclose(K.toarray(), expected, rtol=0, atol=1e-15 * np.abs(expected).max())


BOUNDARIES = ["clamped", "pinned", {"u0": "clamped", "v1": "pinned"}]


@pytest.mark.parametrize("boundary", BOUNDARIES)
@pytest.mark.parametrize("lumped", [False, True])
def test_reduced_matrices_equal_the_reduction_of_the_full_ones(boundary, lumped):
    """(T_u ⊗ T_v)ᵀ (A ⊗ B) (T_u ⊗ T_v) = (T_uᵀ A T_u) ⊗ (T_vᵀ B T_v), to rounding (1e-12)."""
    model = sd.Model(sd.shapes.plane(cells=(7, 5)), PLATE, boundary=boundary)
    K, M = full_matrices(model.gram_u, model.gram_v, PLATE, lumped)
    terms = [(PLATE.w10, 1, 0), (PLATE.w01, 0, 1), (PLATE.w20, 2, 0), (2 * PLATE.w11, 1, 1),
             (PLATE.w02, 0, 2)]
    K_kron = sum(w * sp.kron(model.gram_u[a], model.gram_v[b]) for w, a, b in terms)
    np.testing.assert_allclose(K.toarray(), K_kron.toarray(), rtol=0,
                               atol=1e-12 * abs(K_kron).max())
    T = model.constraints.T
    K_r, M_r, C_r = reduced_matrices(model.gram_u, model.gram_v, PLATE, lumped,
                                     model.constraints)
    C = (PLATE.damping / PLATE.mass) * M + PLATE.rayleigh * K_kron
    for got, full in ((K_r, K_kron), (M_r, M), (C_r, C)):
        expected = (T.T @ full @ T).toarray()
        np.testing.assert_allclose(got.toarray(), expected, rtol=0,
                                   atol=1e-12 * np.abs(expected).max())


def test_fixed_points_off_the_tensor_structure_take_the_general_reduction():
    fixed = np.zeros((10, 8), bool)
    fixed[3, 4] = True
    model = sd.Model(sd.shapes.plane(cells=(7, 5)), PLATE, boundary="clamped", fixed=fixed)
    assert model.constraints.T_u is None
    assert reduced_matrices(model.gram_u, model.gram_v, PLATE, False,
                            model.constraints) is None
    T = model.constraints.T
    expected = (T.T @ model.K_full @ T).toarray()
    np.testing.assert_allclose(model.matrices()[2].toarray(), expected, rtol=0,
                               atol=1e-12 * np.abs(expected).max())


def test_the_whole_net_matrices_wait_until_asked_for_and_equal_the_kronecker_sums():
    """A tensor-product constraint needs only the reduced matrices; K_full and M_full are
    assembled when first read, the same as assembling them directly (to the last bit is not
    asked: 1e-15 of the largest entry, a few roundings of sums of O(1) products)."""
    model = sd.Model(sd.shapes.plane(cells=(7, 5)), PLATE, boundary="clamped")
    assert model._full is None
    K, M = full_matrices(model.gram_u, model.gram_v, PLATE)
    for got, expected in ((model.K_full, K), (model.M_full, M)):
        np.testing.assert_allclose(got.toarray(), expected.toarray(), rtol=0,
                                   atol=1e-15 * abs(expected).max())
    M_r, C_r, K_r = model.matrices()
    expected = (PLATE.damping / PLATE.mass) * M_r + PLATE.rayleigh * K_r
    np.testing.assert_allclose(C_r.toarray(), expected.toarray(), rtol=0,
                               atol=1e-15 * abs(expected).max())


OTHER = sd.Material(mass=0.7, damping=0.1, rayleigh=2e-3, w10=3.0, w01=0.0, w20=0.5,
                    w11=0.0, w02=4.0)


@pytest.mark.parametrize("boundary", BOUNDARIES)
@pytest.mark.parametrize("mass_matrix", ["consistent", "lumped"])
def test_a_model_with_another_material_shares_its_factors_and_equals_one_built_anew(
        boundary, mass_matrix):
    """``with_material`` re-weights the shared reduced 1-D Gram matrices (a weight set to 0
    drops its term): the same products of the same factors as a model built with that
    material, so equal to a few roundings of O(max |entry|) (1e-12 relative)."""
    surface = sd.shapes.plane(cells=(7, 5))
    first = sd.Model(surface, PLATE, boundary=boundary, mass_matrix=mass_matrix)
    shared = first.with_material(OTHER)
    anew = sd.Model(surface, OTHER, boundary=boundary, mass_matrix=mass_matrix)
    assert shared.constraints is first.constraints and shared.gram_u is first.gram_u
    for A, B in zip(shared.matrices(), anew.matrices()):
        np.testing.assert_allclose(A.toarray(), B.toarray(), rtol=0,
                                   atol=1e-12 * np.abs(B.toarray()).max())
    # and the first model's own matrices are left as they were
    np.testing.assert_allclose(first.matrices()[2].toarray(),
                               sd.Model(surface, PLATE, boundary=boundary,
                                        mass_matrix=mass_matrix).matrices()[2].toarray(),
                               rtol=0, atol=1e-12 * np.abs(first.matrices()[2].toarray()).max())


def test_a_model_without_kronecker_factors_is_built_anew_with_the_other_material():
    """Fixed control points that leave no rectangle (no T_u, T_v): a new Model, equal."""
    surface = sd.shapes.plane(cells=(5, 5))
    fixed = np.zeros(surface.shape, dtype=bool)
    fixed[2, 3] = fixed[0, 0] = True
    first = sd.Model(surface, PLATE, boundary="free", fixed=fixed)
    assert first.constraints.T_u is None
    shared = first.with_material(OTHER)
    anew = sd.Model(surface, OTHER, boundary="free", fixed=fixed)
    for A, B in zip(shared.matrices(), anew.matrices()):   # one code path: a few roundings
        np.testing.assert_allclose(A.toarray(), B.toarray(), rtol=0,
                                   atol=1e-12 * np.abs(B.toarray()).max())
