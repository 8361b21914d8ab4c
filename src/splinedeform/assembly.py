"""Galerkin matrices of the parametric model by Kronecker products of 1-D Gram matrices.

For every coordinate alike (DESIGN.md §1.5)::

    M = μ G0u⊗G0v                    (or its row-sum lumped diagonal)
    K = w10 G1u⊗G0v + w01 G0u⊗G1v + w20 G2u⊗G0v + 2 w11 G1u⊗G1v + w02 G0u⊗G2v

with exact 1-D Gram matrices ``G_a`` (:func:`splinedeform.quadrature.gram_matrix`).
Constraints of tensor-product form ``T = T_u ⊗ T_v`` reduce each factor apart,
``Tᵀ (A ⊗ B) T = (T_uᵀ A T_u) ⊗ (T_vᵀ B T_v)``, so the reduced matrices are assembled
from 1-D matrices without forming ``Tᵀ K T``. Every sum of Kronecker products is built
directly in compressed form on the union of the terms' patterns (:func:`kronecker_sum`).
"""

from __future__ import annotations

from typing import Any, Sequence

import numpy as np
import scipy.sparse as sp

from .errors import InputError
from .material import Material
from .physics import intrinsic, rational_plate
from .quadrature import gram_matrix
from .surface import Surface


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
    materials on that geometry share."""

    def __init__(self, u: list[sp.csr_matrix], v: list[sp.csr_matrix]) -> None:
        self.u, self.v = u, v
        self._layouts: dict[tuple[tuple[int, int], ...], KroneckerLayout] = {}

    def layout(self, orders: Sequence[tuple[int, int]]) -> KroneckerLayout:
        """The CSC layout of sums of ``u[a] ⊗ v[b]`` over ``orders``, made once."""
        key = tuple(orders)
        if key not in self._layouts:
            self._layouts[key] = KroneckerLayout([(self.u[a], self.v[b]) for a, b in key],
                                                 "csc")
        return self._layouts[key]


def reduced_factors(gram_u: list[sp.spmatrix], gram_v: list[sp.spmatrix], constraints: Any
                    ) -> ReducedFactors | None:
    """The reduced 1-D Gram matrices ``(T_uᵀ G_a^u T_u, T_vᵀ G_b^v T_v)``, independent of
    the material; ``None`` unless the constraints are of tensor-product form."""
    T_u, T_v = constraints.T_u, constraints.T_v
    if T_u is None or T_v is None:
        return None
    return ReducedFactors([(T_u.T @ G @ T_u).tocsr() for G in gram_u],
                          [(T_v.T @ G @ T_v).tocsr() for G in gram_v])


def reduced_matrices(gram_u: list[sp.spmatrix], gram_v: list[sp.spmatrix],
                     material: Material, lumped: bool, constraints: Any,
                     factors: ReducedFactors | None = None
                     ) -> tuple[sp.csc_matrix, sp.csc_matrix, sp.csc_matrix] | None:
    """``(K_r, M_r, C_r) = (Tᵀ K T, Tᵀ M T, Tᵀ C T)`` from the reduced 1-D factors, in CSC.

    ``C = (γ/μ) M + β K`` (viscous and Rayleigh damping). ``None`` unless the constraints
    are of tensor-product form (``T_u``, ``T_v`` known). A lumped (diagonal) mass is
    reduced as it is, ``Tᵀ M T``. The consistent ``K_r``, ``M_r`` and ``C_r`` share one
    compressed layout: three sums of Kronecker products of the same 1-D factors.
    ``factors``: those of :func:`reduced_factors` when already at hand (models of one
    geometry and several materials share them and their layouts).
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
    stiff_terms = [(w, i) for i, (w, _, _) in enumerate(stiff, start=1)]
    K, M, C = layout.sums([stiff_terms, [(material.mass, 0)],
                           [(viscous * material.mass, 0)] +
                           [(material.rayleigh * w, i) for w, i in stiff_terms]], shape)
    return K, M, C


def full_matrices(gram_u: list[sp.spmatrix], gram_v: list[sp.spmatrix], material: Material,
                  lumped: bool = False) -> tuple[sp.csr_matrix, sp.csr_matrix]:
    """``(K, M)`` of :func:`stiffness` and :func:`mass` on one shared layout."""
    if lumped:
        return stiffness(gram_u, gram_v, material), mass(gram_u, gram_v, material.mass, True)
    shape = (gram_u[0].shape[0] * gram_v[0].shape[0],) * 2
    K, M = kronecker_sums([stiffness_terms(gram_u, gram_v, material),
                           [(material.mass, gram_u[0], gram_v[0])]], shape)
    return K, M


def kronecker_sum(terms: Sequence[tuple[float, sp.spmatrix, sp.spmatrix]],
                  shape: tuple[int, int] | None = None, format: str = "csr") -> sp.spmatrix:
    """``Σ_t w_t A_t ⊗ B_t`` assembled directly in CSR (or CSC) form (:func:`kronecker_sums`)."""
    return kronecker_sums([terms], shape, format)[0]


def kronecker_sums(sums: Sequence[Sequence[tuple[float, sp.spmatrix, sp.spmatrix]]],
                   shape: tuple[int, int] | None = None, format: str = "csr"
                   ) -> list[sp.spmatrix]:
    """Several sums ``Σ_t w_t A_t ⊗ B_t`` on one shared compressed layout
    (:class:`KroneckerLayout` of all their terms' factors)."""
    cls = sp.csr_matrix if format == "csr" else sp.csc_matrix
    if not any(sums):
        return [cls(shape) for _ in sums]
    pairs = [(A, B) for terms in sums for _, A, B in terms]
    layout = KroneckerLayout(pairs, format)
    index, out = 0, []
    for terms in sums:
        out.append([(w, index + i) for i, (w, _, _) in enumerate(terms)])
        index += len(terms)
    return layout.sums(out, shape)


class KroneckerLayout:
    """The compressed layout of sums ``Σ_t w_t A_t ⊗ B_t`` over fixed factor pairs.

    On the union patterns of all the ``A_t`` and of all the ``B_t``, each stored as a
    padded table ``(line, slot)`` of its compressed lines (rows for CSR, columns for
    CSC), the value of a sum at the entry pair ``((i, e), (k, f))`` is
    ``Σ_t w_t A_t[i, e] B_t[k, f]``: one matrix product ``Aᵀ W B`` of the stacked tables
    (``W = diag w``). Line ``(i, k)`` of ``P_A ⊗ P_B`` (``i n_B + k``) holds the entries
    of line ``i`` of ``P_A`` times those of line ``k`` of ``P_B``, ``e``-major, which is
    also the order of their other indices ``j m_B + l``: the product read in the order
    ``(i, k, e, f)``, less the padding, is the compressed data. The layout and the
    factors' tables are computed once; a sum of other weights is one product.
    """

    def __init__(self, pairs: Sequence[tuple[sp.spmatrix, sp.spmatrix]],
                 format: str = "csr") -> None:
        self.cls = sp.csr_matrix if format == "csr" else sp.csc_matrix
        pairs = [(self.cls(A), self.cls(B)) for A, B in pairs]
        PA = _union_pattern([A for A, _ in pairs])
        PB = _union_pattern([B for _, B in pairs])
        other_a, _ = _table(PA, PA.indices)
        other_b, _ = _table(PB, PB.indices)
        stored = (other_a >= 0)[:, None, :, None] & (other_b >= 0)[None, :, None, :]
        self.indptr = np.zeros(stored.shape[0] * stored.shape[1] + 1, dtype=np.int64)
        np.cumsum(np.outer(np.diff(PA.indptr), np.diff(PB.indptr)).ravel(),
                  out=self.indptr[1:])
        width_b = PB.shape[1] if format == "csr" else PB.shape[0]
        self.indices = (other_a[:, None, :, None] * width_b
                        + other_b[None, :, None, :])[stored]
        la, ca = other_a.shape
        lb, cb = other_b.shape
        # where each stored (i, k, e, f) sits in the product's (i e, k f) layout
        i, k, e, f = np.nonzero(stored)
        self.positions = ((i * ca + e) * lb + k) * cb + f
        self.full_shape = (PA.shape[0] * PB.shape[0], PA.shape[1] * PB.shape[1])
        self.values_a = np.stack([_table(PA, _values_on(A, PA))[0] for A, _ in pairs])
        self.values_b = np.stack([_table(PB, _values_on(B, PB))[0] for _, B in pairs])

    def sums(self, sums: Sequence[Sequence[tuple[float, int]]],
             shape: tuple[int, int] | None = None) -> list[sp.spmatrix]:
        """``Σ_t w_t A_t ⊗ B_t`` for each list of ``(w_t, t)`` (``t``: a pair's index), on
        one copy of the layout's index arrays (theirs, not the layout's, to keep)."""
        indices, indptr = self.indices.copy(), self.indptr.copy()
        out = []
        for terms in sums:
            if terms:
                weights = np.array([w for w, _ in terms], dtype=float)
                index = [t for _, t in terms]
                values_a, values_b = self.values_a[index], self.values_b[index]
                with np.errstate(over="ignore", invalid="ignore"):  # scales are checked later
                    product = ((values_a * weights[:, None, None]).reshape(len(terms), -1).T
                               @ values_b.reshape(len(terms), -1))          # (i e, k f)
                data = np.take(product.ravel(), self.positions)
            else:
                data = np.zeros(indices.size)
            matrix = self.cls((data, indices, indptr),
                              shape=self.full_shape if shape is None else shape)
            matrix.has_sorted_indices = True
            out.append(matrix)
        return out


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
    top = lambda b: min(2, b.degree)  # noqa: E731
    return ([gram_matrix(surface.basis_u, a) for a in range(top(surface.basis_u) + 1)],
            [gram_matrix(surface.basis_v, a) for a in range(top(surface.basis_v) + 1)])


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


def _table(pattern: sp.spmatrix, entries: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``entries`` (one per stored position of ``pattern``) as a table ``(line, slot)``.

    Padding slots hold ``-1`` for integer entries and ``0`` for values; returns the table
    and the slot of each stored position.
    """
    counts = np.diff(pattern.indptr)
    line = np.repeat(np.arange(counts.size), counts)
    slot = np.arange(pattern.nnz) - pattern.indptr[line]
    fill = -1 if entries.dtype.kind in "iu" else 0.0
    table = np.full((counts.size, int(counts.max()) if counts.size else 0), fill,
                    dtype=np.int64 if fill == -1 else float)
    table[line, slot] = entries
    return table, slot


def _union_pattern(matrices: Sequence[sp.spmatrix]) -> sp.spmatrix:
    """Sorted compressed pattern of the entries stored in any of ``matrices`` (same format)."""
    pattern = matrices[0].copy()
    pattern.data = np.ones_like(pattern.data)
    for A in matrices[1:]:
        other = A.copy()
        other.data = np.ones_like(other.data)
        pattern = pattern + other
    pattern.sum_duplicates()
    pattern.sort_indices()
    return pattern


def _values_on(A: sp.spmatrix, pattern: sp.spmatrix) -> np.ndarray:
    """Entries of ``A`` at the stored positions of ``pattern`` (zero where ``A`` stores none)."""
    lines = np.repeat(np.arange(pattern.indptr.size - 1), np.diff(pattern.indptr))
    if sp.isspmatrix_csr(pattern):
        return np.asarray(A[lines, pattern.indices]).ravel()
    return np.asarray(A[pattern.indices, lines]).ravel()


def _largest(A: sp.spmatrix) -> float:
    """``max |A_ij|`` (0 for an empty matrix; NaN propagates)."""
    return float(np.abs(A.data).max()) if A.nnz else 0.0
