"""Galerkin matrices of the parametric model by Kronecker products of 1-D Gram matrices.

For every coordinate alike (DESIGN.md §1.5)::

    M = μ G0u⊗G0v                    (or its row-sum lumped diagonal)
    K = w10 G1u⊗G0v + w01 G0u⊗G1v + w20 G2u⊗G0v + 2 w11 G1u⊗G1v + w02 G0u⊗G2v

with exact 1-D Gram matrices ``G_a`` (:func:`splinedeform.quadrature.gram_matrix`).
Constraints of tensor-product form ``T = T_u ⊗ T_v`` reduce each factor apart,
``Tᵀ (A ⊗ B) T = (T_uᵀ A T_u) ⊗ (T_vᵀ B T_v)``, so the reduced matrices are assembled
from 1-D matrices without forming ``Tᵀ K T``. Every sum of Kronecker products is built
directly in compressed form on the union of the terms' patterns
(:mod:`splinedeform.kronecker`, :func:`kronecker_sum`).

What depends on the geometry alone is cached (:mod:`splinedeform.construction_cache`): the
1-D Gram matrices, the 1-D constraint maps, the reduced 1-D factors ``T_uᵀ G_a^u T_u``
(the ``reduced`` cache here, keyed by the bytes of ``T_1d`` and the ``G_a``) and the
Kronecker layouts, so that a model built again on the same net assembles only the weighted
sums. ``splinedeform.construction_cache.clear_caches()`` empties them.
"""

from __future__ import annotations

from typing import Any, Sequence

import numpy as np
import scipy.sparse as sp

from .construction_cache import BoundedCache, read_only
from .errors import InputError
from .kronecker import KroneckerLayout, compressed, content, kronecker_sum, kronecker_sums
from .material import Material
from .physics import intrinsic, rational_plate
from .quadrature import gram_set
from .surface import Surface

__all__ = ["KroneckerLayout", "kronecker_sum", "kronecker_sums", "full_matrices",
           "reduced_matrices", "masked_matrices", "reduced_factors", "gram_matrices",
           "patch_matrices"]

_REDUCED = BoundedCache("reduced", 64, 64 * 2**20,
                        lambda factors: sum(G.data.nbytes + G.indices.nbytes
                                            + G.indptr.nbytes for G in factors))


def stiffness_terms(gram_u: Sequence[sp.spmatrix], gram_v: Sequence[sp.spmatrix],
                    material: Material) -> list[tuple[float, sp.spmatrix, sp.spmatrix]]:
    """The non-zero terms ``(w_ab, G_a^u, G_b^v)`` of ``K`` (the twist weight doubled)."""
    return [(weight, gram_u[a], gram_v[b]) for weight, a, b in _weighted_orders(material)
            if weight]


def _weighted_orders(material: Material) -> list[tuple[float, int, int]]:
    """``(w_ab, a, b)`` of the five terms of ``K`` (the twist weight doubled)."""
    return [(material.w10, 1, 0), (material.w01, 0, 1), (material.w20, 2, 0),
            (2 * material.w11, 1, 1), (material.w02, 0, 2)]


def stiffness(gram_u: list[sp.spmatrix], gram_v: list[sp.spmatrix], material: Material
              ) -> sp.csr_matrix:
    """``K = w10 G1u⊗G0v + w01 G0u⊗G1v + w20 G2u⊗G0v + 2 w11 G1u⊗G1v + w02 G0u⊗G2v``."""
    shape = (gram_u[0].shape[0] * gram_v[0].shape[0],) * 2
    return kronecker_sum(stiffness_terms(gram_u, gram_v, material), shape)


def mass(gram_u: list[sp.spmatrix], gram_v: list[sp.spmatrix], density: float,
         lumped: bool = False) -> sp.csr_matrix:
    """``M = μ G0u⊗G0v``, or lumped: ``μ diag(rowsum G0u ⊗ rowsum G0v)``."""
    if lumped:
        rows = np.kron(np.asarray(gram_u[0].sum(axis=1)).ravel(),
                       np.asarray(gram_v[0].sum(axis=1)).ravel())
        return sp.diags(density * rows, format="csr")
    return kronecker_sum([(density, gram_u[0], gram_v[0])])


class ReducedFactors:
    """The reduced 1-D Gram matrices ``T_uᵀ G_a^u T_u`` (``u``) and ``T_vᵀ G_b^v T_v``
    (``v``) of one geometry, and the compressed layouts of their sums
    (:class:`KroneckerLayout`) by the orders ``(a, b)`` they sum: what models of several
    materials on that geometry share. The factors are CSC (the layouts' format), their
    arrays read-only (the ``reduced`` cache's)."""

    def __init__(self, u: list[sp.csc_matrix], v: list[sp.csc_matrix]) -> None:
        self.u, self.v = u, v
        self._layouts: dict[tuple[tuple[int, int], ...], KroneckerLayout] = {}

    def layout(self, orders: Sequence[tuple[int, int]]) -> KroneckerLayout:
        """The CSC layout of sums of ``u[a] ⊗ v[b]`` over ``orders``, made once."""
        key = tuple(orders)
        if key not in self._layouts:
            self._layouts[key] = KroneckerLayout.of([(self.u[a], self.v[b]) for a, b in key],
                                                    "csc")
        return self._layouts[key]


def reduced_factors(gram_u: list[sp.spmatrix], gram_v: list[sp.spmatrix], constraints: Any
                    ) -> ReducedFactors | None:
    """The reduced 1-D Gram matrices ``(T_uᵀ G_a^u T_u, T_vᵀ G_b^v T_v)``, independent of
    the material; ``None`` unless the constraints are of tensor-product form."""
    T_u, T_v = constraints.T_u, constraints.T_v
    if T_u is None or T_v is None:
        return None
    return ReducedFactors(_reduced(gram_u, T_u), _reduced(gram_v, T_v))


def _reduced(grams: Sequence[sp.spmatrix], T: sp.spmatrix) -> list[sp.csc_matrix]:
    """``[T_1dᵀ G_a T_1d]`` of one direction, from the ``reduced`` cache
    (:mod:`splinedeform.construction_cache`; keyed by the matrices' bytes, read-only)."""
    key = tuple(content(A) for A in (T, *grams))

    def make() -> tuple[sp.csc_matrix, ...]:
        out = []
        for G in grams:
            R = (T.T @ G @ T).tocsc()
            R.sum_duplicates()
            read_only(R.data, R.indices, R.indptr)
            out.append(R)
        return tuple(out)

    return list(_REDUCED.get(key, make))


def reduced_matrices(gram_u: list[sp.spmatrix], gram_v: list[sp.spmatrix],
                     material: Material, lumped: bool, constraints: Any,
                     factors: ReducedFactors | None = None, keep: np.ndarray | None = None
                     ) -> tuple[sp.csc_matrix, sp.csc_matrix, sp.csc_matrix] | None:
    """``(K_r, M_r, C_r) = (Tᵀ K T, Tᵀ M T, Tᵀ C T)`` from the reduced 1-D factors, in CSC.

    ``C = (γ/μ) M + β K`` (viscous and Rayleigh damping). ``None`` unless the constraints
    are of tensor-product form (``T_u``, ``T_v`` known). A lumped (diagonal) mass is
    reduced as it is, ``Tᵀ M T``. The consistent ``K_r``, ``M_r`` and ``C_r`` share one
    compressed layout: ``K_r`` and ``M_r`` two sums of Kronecker products of the same 1-D
    factors, ``C_r`` their combination entry by entry.
    ``factors``: those of :func:`reduced_factors` when already at hand (models of one
    geometry and several materials share them and their layouts). ``keep`` (consistent
    mass only): the principal submatrices ``[keep][:, keep]`` only, on the restricted
    layout (:meth:`~splinedeform.kronecker.KroneckerLayout.restricted`).
    """
    if factors is None:
        factors = reduced_factors(gram_u, gram_v, constraints)
    if factors is None:
        return None
    shape = (factors.u[0].shape[0] * factors.v[0].shape[0],) * 2
    viscous = material.damping / material.mass
    if lumped:
        T = constraints.T
        K = kronecker_sum(stiffness_terms(factors.u, factors.v, material), shape, "csc")
        M = (T.T @ mass(gram_u, gram_v, material.mass, True) @ T).tocsc()
        return K, M, (viscous * M + material.rayleigh * K).tocsc()
    stiff = [(w, a, b) for w, a, b in _weighted_orders(material) if w]
    # the orders summed: the mass's (0, 0) first, then the stiffness's
    layout = factors.layout([(0, 0)] + [(a, b) for _, a, b in stiff])
    if keep is not None:
        layout = layout.restricted(keep)
        shape = (keep.size, keep.size)
    stiff_terms = [(w, i) for i, (w, _, _) in enumerate(stiff, start=1)]
    K, M = layout.sums([stiff_terms, [(material.mass, 0)]], shape)
    with np.errstate(over="ignore", invalid="ignore"):      # scales are checked later
        damping = np.multiply(M.data, viscous)
        damping += material.rayleigh * K.data
        C = compressed(sp.csc_matrix, damping, K.indices, K.indptr, shape)  # K's, M's layout
    return K, M, C


def masked_matrices(gram_u: list[sp.spmatrix], gram_v: list[sp.spmatrix],
                    material: Material, lumped: bool, constraints: Any
                    ) -> tuple[sp.csc_matrix, sp.csc_matrix, sp.csc_matrix] | None:
    """``(K_r, M_r, C_r)`` of fixed points that leave no rectangle free, in CSC.

    ``T = (T_u ⊗ T_v)[:, c]`` (:attr:`~splinedeform.boundary.Constraints.masked`), so
    ``Tᵀ A T = ((T_u ⊗ T_v)ᵀ A (T_u ⊗ T_v))[c][:, c]``: the principal submatrices ``c`` of
    the matrices :func:`reduced_matrices` makes from the factors of ``T_u`` and ``T_v``,
    summed on the restricted layout only.
    ``None`` without such a map, or for a lumped mass (its ``Tᵀ M T`` is made as it is).
    """
    masked = getattr(constraints, "masked", None)
    if masked is None or lumped:
        return None
    T_u, T_v, columns = masked
    factors = ReducedFactors(_reduced(gram_u, T_u), _reduced(gram_v, T_v))
    return reduced_matrices(gram_u, gram_v, material, False, constraints, factors, columns)


def full_matrices(gram_u: list[sp.spmatrix], gram_v: list[sp.spmatrix], material: Material,
                  lumped: bool = False) -> tuple[sp.csr_matrix, sp.csr_matrix]:
    """``(K, M)`` of :func:`stiffness` and :func:`mass` on one shared layout."""
    if lumped:
        return stiffness(gram_u, gram_v, material), mass(gram_u, gram_v, material.mass, True)
    shape = (gram_u[0].shape[0] * gram_v[0].shape[0],) * 2
    K, M = kronecker_sums([stiffness_terms(gram_u, gram_v, material),
                           [(material.mass, gram_u[0], gram_v[0])]], shape)
    return K, M


def check_bending(surface: Surface, material: Material) -> None:
    """Refuse bending weights that a patch's bases cannot carry.

    ``w20`` (``w02``) needs degree ``>= 2`` in ``u`` (``v``) (second derivatives). A
    ``C^0`` knot line is integrated span by span, and the model couples the rotation
    across it (:mod:`splinedeform.physics.coupling_model`).
    """
    for name, basis, weight in (("u", surface.basis_u, material.w20),
                                ("v", surface.basis_v, material.w02)):
        if weight and basis.degree < 2:
            raise InputError(f"bending weight w{'20' if name == 'u' else '02'} needs degree "
                             f">= 2 in {name} (second derivatives), got {basis.degree}")


def gram_matrices(surface: Surface) -> tuple[list[sp.csr_matrix], list[sp.csr_matrix]]:
    """The 1-D Gram matrices ``G_a = ∫ N^(a) N^(a)ᵀ`` of both directions, ``a ≤ min(2, n)``."""
    return (gram_set(surface.basis_u, range(min(2, surface.basis_u.degree) + 1)),
            gram_set(surface.basis_v, range(min(2, surface.basis_v.degree) + 1)))


def patch_matrices(surface: Surface, material: Material, physics: str, lumped: bool
                   ) -> tuple[list[sp.csr_matrix] | None, list[sp.csr_matrix] | None,
                              sp.csr_matrix, sp.csr_matrix]:
    """One patch's 1-D Gram matrices and full ``(K, M)`` (``n_u n_v`` square).

    ``parametric``: ``K = Σ w G_a^u ⊗ G_b^v``, ``M = μ G_0^u ⊗ G_0^v`` (module docstring),
    or, for general weights (:attr:`~splinedeform.Surface.net_weights`), element by
    element on the rational basis (:func:`splinedeform.physics.rational_plate.matrices`;
    no Gram factors: ``None, None``); ``intrinsic``:
    :func:`splinedeform.physics.intrinsic.matrices`. ``lumped`` replaces ``M`` by its row
    sums on the diagonal. Returns ``(gram_u, gram_v, K, M)``.
    """
    if surface.net_weights is not None:
        if physics == "intrinsic":
            K, M = intrinsic.matrices(surface, material, lumped)
        else:
            K, M = rational_plate.matrices(surface.basis_u, surface.basis_v,
                                           surface.net_weights, material)
            if lumped:
                M = sp.diags(np.asarray(M.sum(axis=1)).ravel(), format="csr")
        return None, None, K, M
    gram_u, gram_v = gram_matrices(surface)
    if physics == "intrinsic":
        K, M = intrinsic.matrices(surface, material, lumped)
    else:
        K, M = full_matrices(gram_u, gram_v, material, lumped)
    return gram_u, gram_v, K, M


def _largest(A: sp.spmatrix) -> float:
    """``max |A_ij| = max(max A_ij, -min A_ij)`` (0 for an empty matrix; NaN propagates;
    no array of the absolute values is made)."""
    return float(max(A.data.max(), -A.data.min())) if A.nnz else 0.0
