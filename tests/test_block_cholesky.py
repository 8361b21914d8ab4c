"""The block bidiagonal Cholesky (solvers/block_cholesky.py) against dense solves."""

import numpy as np
import pytest
import scipy.sparse as sp

import splinedeform as sd
from splinedeform.solvers import block_cholesky
from splinedeform.solvers.block_cholesky import BlockCholesky
from splinedeform.solvers.factor import half_bandwidth

PLATE = sd.Material(mass=1.0, damping=0.8, rayleigh=5e-4, w10=10.0, w01=10.0, w20=1.0,
                    w11=1.0, w02=1.0)


def plate_stiffness(cells=(8, 6)):
    return sd.Model(sd.shapes.plane(cells=cells), PLATE, boundary="clamped").matrices()[2]


@pytest.mark.parametrize("width", [None, "band", "band+5"])
@pytest.mark.parametrize("columns", [1, 3, 16])
def test_the_block_factor_solves_the_plate_stiffness_like_a_dense_solve(width, columns):
    """Blocks as wide as the band (every coupling block square and triangular), wider
    (a short last block: the rectangular product), and the default."""
    K = plate_stiffness()
    b = half_bandwidth(K)
    w = {None: None, "band": b, "band+5": b + 5}[width]
    F = np.random.default_rng(0).normal(size=(K.shape[0], columns))
    expected = np.linalg.solve(K.toarray(), F)
    solved = BlockCholesky(K, w).solve(F)
    # cond(K) ≈ 1e4 here: 1e-10 relative leaves a margin of 1e2 over cond · eps
    np.testing.assert_allclose(solved, expected, rtol=0, atol=1e-10 * np.abs(expected).max())
    vector = BlockCholesky(K, w).solve(F[:, 0])
    assert vector.shape == (K.shape[0],)
    np.testing.assert_allclose(vector, expected[:, 0], rtol=0,
                               atol=1e-10 * np.abs(expected).max())


def test_a_matrix_that_is_not_positive_definite_is_refused():
    K = plate_stiffness()
    A = K - 2.0 * sp.identity(K.shape[0]) * K.diagonal().max()
    with pytest.raises(np.linalg.LinAlgError):
        BlockCholesky(A)
    with pytest.raises(ValueError, match="below the half bandwidth"):
        BlockCholesky(K, half_bandwidth(K) - 1)


def test_the_band_solve_is_kept_while_the_band_stays_in_cache(monkeypatch):
    K = plate_stiffness()
    assert block_cholesky.block_cholesky(K) is None
    monkeypatch.setattr(block_cholesky, "CACHED_BAND", 0)
    assert isinstance(block_cholesky.block_cholesky(K), BlockCholesky)
    monkeypatch.setattr(block_cholesky, "BLOCK_BYTES", 0)
    assert block_cholesky.block_cholesky(K) is None
    monkeypatch.setattr(block_cholesky, "BLOCK_BYTES", 2**30)
    monkeypatch.setattr(block_cholesky, "CACHED_BAND", 0)
    assert block_cholesky.block_cholesky(-K) is None
