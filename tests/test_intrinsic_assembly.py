"""The intrinsic plate's matrices, cell by cell, against a point-by-point COO sum.

Reference: ``K_kl = Σ_q w_q √g_q [T g^αβ N_k,α N_l,β + D (Δ_S N_k)(Δ_S N_l)]`` and
``M_kl = Σ_q w_q √g_q μ N_k N_l`` with one dense block per Gauss point added into a COO
matrix (no cells, no Cholesky factor of ``g^αβ``, no pattern).
"""

from math import pi

import numpy as np
import pytest
import scipy.sparse as sp

import splinedeform as sd
from splinedeform.physics import metric
from splinedeform.physics.intrinsic import laplace_beltrami, matrices


def pointwise(surface, material):
    G = metric.grid(surface)
    N = metric.shape_derivatives(G)
    index = metric.global_index(G, surface.basis_v.size)
    dA = G.weight * G.sqrt_g
    grad = np.stack([N[1, 0], N[0, 1]])
    K = np.einsum("abij,iabk,jabl->abkl", (material.w10 * dA)[..., None, None] * G.g_inv,
                  grad, grad)
    L = laplace_beltrami(G, N)
    K += (material.w20 * dA)[..., None, None] * L[..., :, None] * L[..., None, :]
    M = (material.mass * dA)[..., None, None] * N[0, 0][..., :, None] * N[0, 0][..., None, :]
    n = surface.basis_u.size * surface.basis_v.size

    def coo(blocks):
        rows = np.broadcast_to(index[..., :, None], blocks.shape).ravel()
        cols = np.broadcast_to(index[..., None, :], blocks.shape).ravel()
        return sp.coo_matrix((blocks.ravel(), (rows, cols)), shape=(n, n)).tocsr()
    return coo(K), coo(M)


@pytest.mark.parametrize("surface", [
    sd.shapes.tile(radius=2.0, angle=80 * pi / 180, length=3.0, cells=(5, 4)),
    sd.shapes.cylinder(radius=1.0, height=2.0, cells=(8, 3)),
    sd.shapes.plane(cells=(3, 4), degree=2, knots=("uniform", "open"))],
    ids=["tile", "periodic", "quadratic-uniform"])
@pytest.mark.parametrize("T, D", [(1.0, 0.01), (1.0, 0.0), (0.0, 0.02)])
def test_intrinsic_matrices_equal_the_pointwise_sum(surface, T, D):
    material = sd.Material(mass=1.7, w10=T, w01=T, w20=D, w11=D, w02=D)
    K, M = matrices(surface, material)
    K0, M0 = pointwise(surface, material)
    # the same sums in another order: round-off (measured 7e-16 relative)
    assert abs(K - K0).max() <= 1e-12 * abs(K0).max()
    assert abs(M - M0).max() <= 1e-12 * abs(M0).max()
    assert abs(K - K.T).max() <= 1e-14 * abs(K0).max()
    lumped = matrices(surface, material, lumped=True)[1]
    np.testing.assert_allclose(lumped.diagonal(), np.asarray(M0.sum(axis=1)).ravel(),
                               rtol=1e-12)    # row sums of the consistent mass, round-off
