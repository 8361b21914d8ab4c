"""The factorisation of the constrained stiffness (solvers/factor.py) against dense solves."""

import numpy as np
import pytest
import scipy.sparse as sp

import splinedeform as sd
from splinedeform.errors import InputError
from splinedeform.solvers import factor
from splinedeform.solvers.factor import factorise, half_bandwidth

PLATE = sd.Material(mass=1.0, damping=0.8, rayleigh=5e-4, w10=10.0, w01=10.0, w20=1.0,
                    w11=1.0, w02=1.0)


def plate_stiffness(cells=(8, 6)):
    return sd.Model(sd.shapes.plane(cells=cells), PLATE, boundary="clamped").matrices()[2]


@pytest.mark.parametrize("method", ["auto", "banded", "superlu"])
def test_each_method_solves_the_plate_stiffness_like_a_dense_solve(method):
    K = plate_stiffness()
    F = np.random.default_rng(0).normal(size=(K.shape[0], 3))
    expected = np.linalg.solve(K.toarray(), F)
    solved = factorise(K, method)
    assert solved.method == ("banded" if method == "auto" else method)
    # cond(K) ≈ 1e4 here: 1e-10 relative leaves a margin of 1e2 over cond · eps
    np.testing.assert_allclose(solved.solve(F), expected, rtol=0,
                               atol=1e-10 * np.abs(expected).max())
    np.testing.assert_allclose(solved.solve(F[:, 0]), expected[:, 0], rtol=0,
                               atol=1e-10 * np.abs(expected).max())


def test_the_kronecker_ordering_has_the_closed_form_half_bandwidth():
    """Free coordinate (k, l) couples (k', l') with |k-k'|, |l-l'| <= n: b = n m_v + n."""
    cells_u, cells_v, n = 8, 6, 3
    K = plate_stiffness((cells_u, cells_v))
    free_v = cells_v + n - 4                       # clamped: two rows off at each end
    assert half_bandwidth(K) == n * free_v + n
    assert half_bandwidth(sp.identity(4, format="csr")) == 0


@pytest.mark.parametrize("shape", [(40, 40), (30, 45), (45, 30)])
def test_the_half_bandwidth_of_every_storage_is_the_largest_offset_of_its_entries(shape):
    """Compressed storage with sorted indices reads only each column's (row's) first and
    last index; unsorted, coordinate and rectangular matrices count every entry. The
    expected value is ``max |i − j|`` over the coordinates (integers: exact)."""
    rng = np.random.default_rng(3)
    A = sp.random(*shape, density=0.08, random_state=rng, format="coo")
    expected = int(np.abs(A.row - A.col).max())
    for form in (A, A.tocsc(), A.tocsr()):
        assert half_bandwidth(form) == expected
    shuffled = A.tocsr()
    order = np.concatenate([rng.permutation(np.arange(a, b))
                            for a, b in zip(shuffled.indptr[:-1], shuffled.indptr[1:])])
    shuffled = sp.csr_matrix((shuffled.data[order], shuffled.indices[order],
                              shuffled.indptr), shape=shape)
    shuffled.has_sorted_indices = False
    assert half_bandwidth(shuffled) == expected
    assert half_bandwidth(sp.csc_matrix(shape)) == 0      # no entries


def test_auto_leaves_the_band_when_its_storage_is_too_large(monkeypatch):
    monkeypatch.setattr(factor, "BAND_BYTES", 0)
    monkeypatch.setattr(factor, "_cholmod", lambda: None)
    assert factorise(plate_stiffness()).method == "superlu"


def test_an_indefinite_matrix_falls_back_to_lu_and_a_singular_one_raises():
    A = sp.csc_matrix(np.array([[2.0, 1.0, 0.0], [1.0, -3.0, 1.0], [0.0, 1.0, 2.0]]))
    b = np.array([1.0, 2.0, 3.0])
    solved = factorise(A, "banded")               # not positive definite: Cholesky fails
    assert solved.method == "superlu"
    # a 3x3 well-conditioned system: agreement to rounding
    np.testing.assert_allclose(A @ solved.solve(b), b, rtol=0, atol=1e-14)
    singular = sp.csc_matrix(np.array([[1.0, 1.0], [1.0, 1.0]]))
    with pytest.raises(RuntimeError):
        factorise(singular).solve(np.ones(2))


def test_bad_requests_say_what_is_allowed():
    with pytest.raises(InputError, match="one of"):
        factorise(plate_stiffness(), "umfpack")
    with pytest.raises(InputError, match="square"):
        factorise(sp.csr_matrix((2, 3)))


def test_static_solve_uses_it_and_matches_a_dense_solve():
    model = sd.Model(sd.shapes.plane(cells=(8, 6)), PLATE, boundary="clamped")
    load = sd.Point(0.4, 0.3, (0.0, 0.0, -1.0))
    F = model.load_vector(load)
    expected = np.linalg.solve(model.matrices()[2].toarray(), F)
    d = model.static(load).d_free
    # as above: cond(K) · eps ≈ 1e-12, 1e-10 with margin
    np.testing.assert_allclose(d, expected, rtol=0, atol=1e-10 * np.abs(expected).max())


def test_a_second_load_reuses_the_factorisation():
    model = sd.Model(sd.shapes.plane(cells=(6, 6)), PLATE, boundary="clamped")
    first = model.static(sd.Point(0.4, 0.3, (0.0, 0.0, -1.0))).d_free
    kept = model._stiffness_factor
    second = model.static(sd.Point(0.4, 0.3, (0.0, 0.0, -2.0))).d_free
    assert model._stiffness_factor is kept
    # linear in the load: twice the force, twice the displacement (to rounding)
    np.testing.assert_allclose(second, 2 * first, rtol=0, atol=1e-13 * np.abs(second).max())


def test_cholmod_without_scikit_sparse_says_how_to_get_it(monkeypatch):
    monkeypatch.setattr(factor, "_cholmod", lambda: None)
    with pytest.raises(InputError, match="scikit-sparse"):
        factorise(plate_stiffness(), "cholmod")


def test_the_eigen_solutions_factorise_the_plate_by_band_cholesky_and_solve_like_dense():
    """The shift-invert Lanczos and the sparse bases take the band Cholesky for a plate in
    the Kronecker order, and still report a singular stiffness by name."""
    from splinedeform.errors import SingularSystemError
    from splinedeform.solvers.modal_basis import stiffness_factorisation
    from splinedeform.solvers.sparse_eigen import factorise as eigen_factorise

    K = plate_stiffness()
    F = np.random.default_rng(1).normal(size=(K.shape[0], 4))
    expected = np.linalg.solve(K.toarray(), F)
    for made in (eigen_factorise(K), stiffness_factorisation(K)):
        assert made.method == "banded"
        # cond(K) ≈ 1e4: 1e-10 relative is 1e2 above cond · eps
        np.testing.assert_allclose(made.solve(F), expected, rtol=0,
                                   atol=1e-10 * np.abs(expected).max())
    singular = sp.csr_matrix(np.diag([1.0, 2.0, 0.0, 3.0]))
    assert factor.band_cholesky(singular) is None
    with pytest.raises(SingularSystemError, match="singular"):
        eigen_factorise(singular)
    with pytest.raises(SingularSystemError, match="singular"):
        stiffness_factorisation(singular)


def test_band_cholesky_declines_a_band_too_costly_for_its_ordering(monkeypatch):
    K = plate_stiffness()
    monkeypatch.setattr(factor, "BAND_FLOPS", K.shape[0] * half_bandwidth(K) ** 2 - 1)
    assert factor.band_cholesky(K) is None
