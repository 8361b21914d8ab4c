"""Galerkin matrices of the parametric model by Kronecker products of 1-D Gram matrices.

For every coordinate alike (DESIGN.md §1.5)::

    M = μ G0u⊗G0v                    (or its row-sum lumped diagonal)
    K = w10 G1u⊗G0v + w01 G0u⊗G1v + w20 G2u⊗G0v + 2 w11 G1u⊗G1v + w02 G0u⊗G2v

with exact 1-D Gram matrices ``G_a`` (:func:`splinedeform.quadrature.gram_matrix`).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .material import Material


def stiffness(gram_u: list[sp.spmatrix], gram_v: list[sp.spmatrix], material: Material
              ) -> sp.csr_matrix:
    """``K = w10 G1u⊗G0v + w01 G0u⊗G1v + w20 G2u⊗G0v + 2 w11 G1u⊗G1v + w02 G0u⊗G2v``."""
    terms = [(material.w10, 1, 0), (material.w01, 0, 1), (material.w20, 2, 0),
             (2 * material.w11, 1, 1), (material.w02, 0, 2)]
    K = sp.csr_matrix((gram_u[0].shape[0] * gram_v[0].shape[0],) * 2)
    for weight, a, b in terms:
        if weight:
            K = K + weight * sp.kron(gram_u[a], gram_v[b], format="csr")
    return K.tocsr()


def mass(gram_u: list[sp.spmatrix], gram_v: list[sp.spmatrix], density: float,
         lumped: bool = False) -> sp.csr_matrix:
    """``M = μ G0u⊗G0v``, or lumped: ``μ diag(rowsum G0u ⊗ rowsum G0v)``."""
    if lumped:
        rows = np.kron(np.asarray(gram_u[0].sum(axis=1)).ravel(),
                       np.asarray(gram_v[0].sum(axis=1)).ravel())
        return sp.diags(density * rows, format="csr")
    return (density * sp.kron(gram_u[0], gram_v[0], format="csr")).tocsr()


def _largest(A: sp.spmatrix) -> float:
    """``max |A_ij|`` (0 for an empty matrix; NaN propagates)."""
    return float(np.abs(A.data).max()) if A.nnz else 0.0
