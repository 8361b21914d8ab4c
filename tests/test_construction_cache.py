"""The construction caches (construction_cache.py) and the Kronecker assembly on them
(kronecker.py), against dense quadrature, scipy's kron and models built from scratch."""

import numpy as np
import pytest
import scipy.sparse as sp

import splinedeform as sd
from splinedeform.boundary import constraint_map
from splinedeform.construction_cache import BoundedCache, cache_info, clear_caches
from splinedeform.knots import KnotVectorBasis, RationalBasis
from splinedeform.kronecker import KroneckerLayout, kron
from splinedeform.quadrature import gauss_points, gram_matrix

PLATE = sd.Material(mass=1.3, damping=0.8, rayleigh=5e-4, w10=10.0, w01=7.0, w20=1.0,
                    w11=0.5, w02=2.0)
TERMS = [(PLATE.w10, 1, 0), (PLATE.w01, 0, 1), (PLATE.w20, 2, 0), (2 * PLATE.w11, 1, 1),
         (PLATE.w02, 0, 2)]


def dense_gram(basis, order):
    """``Bᵀ diag(w) B`` of the dense collocation matrix at the Gauss points."""
    x, w = gauss_points(basis)
    B = basis(x, order)
    return B.T @ (w[:, None] * B)


def rational_plane(cells=6):
    t = np.r_[0, 0, 0, np.linspace(0, 1, cells + 1)[1:-1], 1, 1, 1]
    knots = KnotVectorBasis(2, t)
    a = 1 + 0.4 * np.sin(np.arange(knots.size))
    b = 1 + 0.3 * np.cos(np.arange(knots.size))
    g = np.linspace(0, 1, knots.size)
    P = np.zeros((knots.size, knots.size, 3))
    P[..., 0], P[..., 1] = g[:, None], g[None, :]
    return sd.Surface(P, RationalBasis(knots, a), RationalBasis(knots, b))


BASES = [sd.shapes.plane(cells=(6, 5)).basis_u,
         sd.shapes.plane(cells=(6, 5), knots="uniform").basis_u,
         sd.shapes.cylinder(cells=(8, 4)).basis_u,
         rational_plane().basis_u]


@pytest.mark.parametrize("basis", BASES, ids=["open", "uniform", "periodic", "rational"])
def test_gram_matrices_equal_dense_quadrature_and_copies_protect_the_cache(basis):
    """Cached or not, ``G_a`` is the dense ``Bᵀ W B`` (sums of a few dozen O(1/h^2a)
    products: 1e-13 of the largest entry); a caller writing into its copy changes nothing
    the next caller gets."""
    clear_caches()
    for order in range(min(2, basis.degree) + 1):
        expected = dense_gram(basis, order)
        for _ in range(2):                                   # made, then from the cache
            G = gram_matrix(basis, order)
            assert G.format == "csr" and G.has_canonical_format
            np.testing.assert_allclose(G.toarray(), expected, rtol=0,
                                       atol=1e-13 * np.abs(expected).max())
            G.data[:] = 0.0
    assert cache_info()["gram"]["hits"] >= 1


def test_a_constraint_map_is_a_copy_of_the_cached_one():
    """Clamped open knots eliminate the two outer coefficients at each end: ``T`` keeps
    the others (0/1 entries, compared to half a unit); writing into it leaves the cache."""
    basis = sd.shapes.plane(cells=(6, 5)).basis_u
    clear_caches()
    T, kept = constraint_map(basis, "clamped", "clamped")
    assert kept.shape == (basis.size - 4,)          # indices: compared to half a unit
    assert np.abs(kept - np.arange(2, basis.size - 2)).max() < 0.5
    T.data[:] = 7.0
    kept[:] = 0
    again, kept_again = constraint_map(basis, "clamped", "clamped")
    expected = np.eye(basis.size)[:, 2:basis.size - 2]
    assert np.abs(again.toarray() - expected).max() < 0.5
    assert np.abs(kept_again - np.arange(2, basis.size - 2)).max() < 0.5


@pytest.mark.parametrize("format", ["csr", "csc"])
def test_kron_equals_scipys_and_one_pattern_serves_other_values(format):
    """One product per entry, so the same roundings as scipy's (to 1e-15 of the largest);
    factors of the same patterns and other values share the cached pattern arrays."""
    rng = np.random.default_rng(3)
    A, B = sp.random(6, 5, 0.5, random_state=rng), sp.random(4, 7, 0.4, random_state=rng)
    expected = sp.kron(A, B).toarray()
    K = kron(A, B, format)
    assert K.format == format and K.has_canonical_format
    K.check_format(full_check=True)
    np.testing.assert_allclose(K.toarray(), expected, rtol=0, atol=1e-15 * np.abs(expected).max())
    first = KroneckerLayout.of([(A, B)], format)
    assert KroneckerLayout.of([(A, B)], format) is first            # the same factors
    other = KroneckerLayout.of([(2 * A, 3 * B)], format)
    assert other is not first and other.indices is first.indices    # the same pattern
    assert not first.indices.flags.writeable


def test_a_bounded_cache_drops_the_least_recently_used_beyond_its_bounds():
    """Counts of entries and bytes (integers, exact)."""
    cache = BoundedCache("test-bounded", 2, 100, lambda value: value)
    for key, size in (("a", 10), ("b", 20), ("a", 0), ("c", 30)):
        cache.get(key, lambda size=size: size)
    assert len(cache) == 2 and cache.bytes == 40          # "b" dropped: "a" was used again
    assert cache.get("a", lambda: -1) == 10
    cache.get("d", lambda: 95)                            # over the bytes: the others go
    assert len(cache) == 1 and cache.bytes == 95
    cache.get("e", lambda: 101)                           # larger than the bound: not kept
    assert len(cache) == 1 and cache.get("e", lambda: 5) == 5
    clear_caches()
    assert len(cache) == 0 and cache.bytes == 0


SURFACES = {"clamped": (sd.shapes.plane(cells=(7, 5)), "clamped"),
            "free": (sd.shapes.plane(cells=(6, 4)), "free"),
            "pinned": (sd.shapes.plane(cells=(6, 5), knots="uniform"), "pinned"),
            "periodic": (sd.shapes.cylinder(cells=(8, 4)), {"v0": "clamped"}),
            "rational": (rational_plane(), "clamped")}


@pytest.mark.parametrize("name", list(SURFACES))
def test_reduced_matrices_equal_the_reduction_of_dense_kronecker_sums(name):
    """``K_r = Tᵀ (Σ w G_a ⊗ G_b) T`` with dense-quadrature ``G`` and scipy's kron,
    ``M_r = μ Tᵀ (G_0 ⊗ G_0) T``, ``C_r = (γ/μ) M_r + β K_r``, from scratch and again
    from the caches (a few roundings of sums of O(max) terms: 1e-12 of the largest entry);
    a model changing its Gram matrices leaves the next model as it was."""
    surface, boundary = SURFACES[name]
    bu, bv = surface.basis_u, surface.basis_v
    gu = [dense_gram(bu, a) for a in range(3)]
    gv = [dense_gram(bv, a) for a in range(3)]
    K = sum(w * np.kron(gu[a], gv[b]) for w, a, b in TERMS)
    M = PLATE.mass * np.kron(gu[0], gv[0])
    clear_caches()
    for _ in range(2):
        model = sd.Model(surface, PLATE, boundary=boundary)
        T = model.T.toarray()
        M_r, C_r, K_r = (A.toarray() for A in model.matrices())
        expected = {"K": T.T @ K @ T, "M": T.T @ M @ T}
        expected["C"] = (PLATE.damping / PLATE.mass) * expected["M"] \
            + PLATE.rayleigh * expected["K"]
        for got, key in ((K_r, "K"), (M_r, "M"), (C_r, "C")):
            np.testing.assert_allclose(got, expected[key], rtol=0,
                                       atol=1e-12 * np.abs(expected[key]).max())
        model.gram_u[0].data[:] = 0.0
    assert cache_info()["reduced"]["hits"] >= 2


def test_principal_submatrices_equal_scipys_selection():
    """``A[keep][:, keep]`` for matrices on one pattern: a selection moves entries without
    arithmetic (compared to 1e-15 of the largest, which any rounding would exceed)."""
    from splinedeform.kronecker import principal_submatrices

    rng = np.random.default_rng(5)
    A = sp.random(30, 30, 0.2, random_state=rng, format="csc")
    A = (A + A.T).tocsc()
    A.sum_duplicates()
    B = A.copy()
    B.data = rng.standard_normal(B.nnz)
    keep = np.flatnonzero(rng.random(30) < 0.6)
    for got, full in zip(principal_submatrices([A, B], keep), (A, B)):
        expected = full.toarray()[np.ix_(keep, keep)]
        assert got.format == "csc" and got.has_canonical_format
        got.check_format(full_check=True)
        np.testing.assert_allclose(got.toarray(), expected, rtol=0,
                                   atol=1e-15 * np.abs(expected).max())


@pytest.mark.parametrize("knots, boundary", [("open", "free"), ("uniform", "clamped")])
def test_a_free_region_that_is_no_rectangle_takes_the_submatrices_of_the_rectangle(
        knots, boundary):
    """Fixed points off a rectangle: ``K_r``, ``M_r``, ``C_r`` equal ``Tᵀ K T`` etc. of
    the whole net's matrices (a few roundings of sums of O(max) terms: 1e-12)."""
    surface = sd.shapes.plane(cells=(7, 6), knots=knots)
    fixed = np.zeros(surface.shape, dtype=bool)
    fixed[3, 4] = fixed[5, 1] = True
    model = sd.Model(surface, PLATE, boundary=boundary, fixed=fixed)
    assert model.constraints.T_u is None and model.constraints.masked is not None
    T = model.T
    K, M = model.K_full, model.M_full
    C = (PLATE.damping / PLATE.mass) * M + PLATE.rayleigh * K
    for got, full in zip(model.matrices(), (M, C, K)):
        expected = (T.T @ full @ T).toarray()
        np.testing.assert_allclose(got.toarray(), expected, rtol=0,
                                   atol=1e-12 * np.abs(expected).max())
