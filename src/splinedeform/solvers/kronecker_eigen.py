"""All modes of a Kronecker-structured model by a cheap reduction to standard form.

With per-edge constraints (``T = T_u ⊗ T_v``) and the consistent mass, every matrix of the
parametric model is a sum of Kronecker products of small reduced 1-D Gram matrices
``G^u_a = T_uᵀ G_a T_u``, ``G^v_b = T_vᵀ G_b T_v``::

    M_r = μ G^u_0 ⊗ G^v_0,     K_r = Σ_t w_t G^u_{a_t} ⊗ G^v_{b_t}.

So the Cholesky factor of ``M_r`` is ``√μ L_u ⊗ L_v`` (``G^u_0 = L_u L_uᵀ``) and the standard
form is a sum of Kronecker products of small dense matrices::

    C = (L_u ⊗ L_v)⁻¹ K_r (L_u ⊗ L_v)⁻ᵀ / μ = Σ_t (w_t/μ) Ĝ^u_{a_t} ⊗ Ĝ^v_{b_t},
    Ĝ^u_a = L_u⁻¹ G^u_a L_u⁻ᵀ   (Ĝ_0 = I),

formed in ``O(n²)`` instead of LAPACK ``sygst``'s ``O(n³)`` reduction. ``C Y = Y Λ``
(``eigh``, driver :data:`DRIVER`) gives ``Φ = (L_u ⊗ L_v)⁻ᵀ Y / √μ`` by two triangular
solves on the grid of each mode, ``O(n^{3/2})`` per mode. Unlike the separable factors this
holds with the twist term ``w11`` too; only the eigen-decomposition of ``C`` is ``O(n³)``.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg as sla
from numpy.typing import NDArray

from .system import KroneckerFactors

Array = NDArray[np.float64]
DRIVER = "evd"
"""LAPACK driver for the standard problem: measured on this project's 2-core machine (one
BLAS thread) the divide-and-conquer ``syevd`` took 0.81 s at n = 900 and 58 s at n = 3969
under load, against 2.1 s and 239 s for ``syevr`` (scipy's default) and 1.3 s and 95 s for
the generalised ``sygvd`` on the same matrices."""


def standard_form(factors: KroneckerFactors) -> tuple[Array, Array, Array]:
    """``(C, L_u, L_v)``: the standard-form matrix and the 1-D Cholesky factors."""
    B_u, B_v = factors.gram_u[0], factors.gram_v[0]
    L_u = np.linalg.cholesky(B_u)
    L_v = np.linalg.cholesky(B_v)

    def hat(L: Array, G: Array) -> Array:
        X = sla.solve_triangular(L, G, lower=True, check_finite=False)
        return sla.solve_triangular(L, X.T, lower=True, check_finite=False).T

    nu, nv = B_u.shape[0], B_v.shape[0]
    C = np.zeros((nu * nv, nu * nv))
    cache: dict[tuple[str, int], Array] = {}
    for weight, a, b in factors.terms():
        for key, L, grams, order in (("u", L_u, factors.gram_u, a),
                                     ("v", L_v, factors.gram_v, b)):
            if (key, order) not in cache:
                cache[key, order] = (np.eye(L.shape[0]) if order == 0
                                     else hat(L, grams[order]))
        C += (weight / factors.mass) * np.kron(cache["u", a], cache["v", b])
    return C, L_u, L_v


def back_transform(Y: Array, L_u: Array, L_v: Array, mass: float) -> Array:
    """``Φ = (L_u ⊗ L_v)⁻ᵀ Y / √μ`` for ``Y`` of shape ``(n_u' n_v', N)``."""
    nu, nv = L_u.shape[0], L_v.shape[0]
    N = Y.shape[1]
    X = sla.solve_triangular(L_u.T, Y.reshape(nu, nv * N), lower=False, check_finite=False)
    X = np.ascontiguousarray(X.reshape(nu, nv, N).transpose(1, 0, 2)).reshape(nv, nu * N)
    X = sla.solve_triangular(L_v.T, X, lower=False, check_finite=False)
    X = X.reshape(nv, nu, N).transpose(1, 0, 2).reshape(nu * nv, N)
    return X / np.sqrt(mass)


def eigenpairs(factors: KroneckerFactors, driver: str = DRIVER) -> tuple[Array, Array]:
    """All ``(λ, Φ)`` of ``K_r φ = λ M_r φ`` (ascending, ``Φᵀ M_r Φ = I``) by the reduction above."""
    C, L_u, L_v = standard_form(factors)
    lam, Y = sla.eigh(C, driver=driver, overwrite_a=True, check_finite=False)
    return lam, back_transform(Y, L_u, L_v, factors.mass)
