"""Sums of Kronecker products ``Σ_t w_t A_t ⊗ B_t`` assembled directly in compressed form.

Line ``(i, k)`` of ``P_A ⊗ P_B`` (``i n_B + k``; rows for CSR, columns for CSC) holds the
entries of line ``i`` of ``P_A`` times those of line ``k`` of ``P_B``, ``e``-major, which
is also the sorted order of their other indices ``j m_B + l``. So on the union patterns
``P_A`` of all the ``A_t`` and ``P_B`` of all the ``B_t``, each stored as a padded table
``(line, slot)``, the value of a sum at the entry pair ``((i, e), (k, f))`` is
``Σ_t w_t A_t[i, e] B_t[k, f]``: one matrix product ``Aᵀ W B`` of the stacked value tables
(``W = diag w``) read at fixed positions. The pattern (``indptr``, ``indices``, the
positions) depends on the two 1-D patterns only and is kept in the ``layout`` cache of
:mod:`splinedeform.construction_cache`; the results are handed to scipy as canonical
compressed arrays (sorted indices, no duplicates, 32-bit indices where they fit), which
it takes without checks of their contents or copies.
"""

from __future__ import annotations

import copy
from typing import Sequence

import numpy as np
import scipy.sparse as sp

from .construction_cache import BoundedCache, read_only

_PATTERNS = BoundedCache("layout", 16, 256 * 2**20, lambda p: p.nbytes)
_FACTORED = BoundedCache("kronecker", 16, 256 * 2**20, lambda layout: layout.nbytes)


def index_dtype(*sizes: int) -> type:
    """32-bit indices when every one of ``sizes`` fits, else 64-bit (scipy's rule)."""
    return np.int32 if max(sizes, default=0) < 2**31 - 1 else np.int64


def compressed(cls: type, data: np.ndarray, indices: np.ndarray, indptr: np.ndarray,
               shape: tuple[int, int]) -> sp.spmatrix:
    """A ``cls`` (csr or csc matrix) on canonical arrays, flagged canonical (no sort, no
    duplicate sum later)."""
    matrix = cls((data, indices, indptr), shape=shape)
    matrix.has_canonical_format = True
    return matrix


def lines(A: sp.spmatrix, format: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(line, other, value)`` of the stored entries of ``A`` in ``format``'s canonical
    order (lines: rows for CSR, columns for CSC), duplicates summed."""
    A = A.asformat(format)
    if not A.has_canonical_format:
        A = A.copy()
        A.sum_duplicates()
    line = np.repeat(np.arange(A.indptr.size - 1), np.diff(A.indptr))
    return line, A.indices.astype(np.int64), A.data


class _Pattern:
    """The compressed pattern of ``P_A ⊗ P_B`` from the two padded tables of other indices
    (``-1``: padding): ``indptr``, ``indices`` and each stored entry's position in the
    product ``(i e, k f)``."""

    def __init__(self, other_a: np.ndarray, other_b: np.ndarray, width_b: int,
                 counts_a: np.ndarray, counts_b: np.ndarray) -> None:
        (la, ca), (lb, cb) = other_a.shape, other_b.shape
        stored = (other_a >= 0)[:, None, :, None] & (other_b >= 0)[None, :, None, :]
        nnz = int(counts_a.sum()) * int(counts_b.sum())
        dtype = index_dtype(nnz, la * lb + 1, la * ca * lb * cb,
                            (int(other_a.max(initial=0)) + 1) * width_b)
        self.indptr = np.zeros(la * lb + 1, dtype=dtype)
        np.cumsum(np.outer(counts_a, counts_b).ravel(), out=self.indptr[1:])
        self.indices = ((other_a * width_b).astype(dtype)[:, None, :, None]
                        + other_b.astype(dtype)[None, :, None, :])[stored]
        # where each stored (i, k, e, f) sits in the product's (i e, k f) layout
        at_a = (np.arange(la * ca, dtype=dtype) * (lb * cb)).reshape(la, ca)
        at_b = np.arange(lb * cb, dtype=dtype).reshape(lb, cb)
        self.positions = (at_a[:, None, :, None] + at_b[None, :, None, :])[stored]
        read_only(self.indptr, self.indices, self.positions)
        self.nbytes = self.indptr.nbytes + self.indices.nbytes + self.positions.nbytes


class _Restricted:
    """A :class:`_Pattern` restricted to the principal submatrix ``keep`` of a layout."""

    def __init__(self, layout: "KroneckerLayout", keep: np.ndarray) -> None:
        entries, self.indices, self.indptr = _principal(layout.indptr, layout.indices,
                                                        layout.full_shape[0], keep)
        self.positions = layout.positions[entries]
        read_only(self.indptr, self.indices, self.positions)
        self.nbytes = self.indptr.nbytes + self.indices.nbytes + self.positions.nbytes


class KroneckerLayout:
    """The compressed layout of sums ``Σ_t w_t A_t ⊗ B_t`` over fixed factor pairs
    (module docstring): the cached pattern of the two union patterns and the factors'
    value tables; a sum of other weights is one product and one gather."""

    def __init__(self, pairs: Sequence[tuple[sp.spmatrix, sp.spmatrix]],
                 format: str = "csr") -> None:
        self.cls = sp.csr_matrix if format == "csr" else sp.csc_matrix
        a_lines = [lines(A, format) for A, _ in pairs]
        b_lines = [lines(B, format) for _, B in pairs]
        shape_a, shape_b = pairs[0][0].shape, pairs[0][1].shape
        width_a = shape_a[1] if format == "csr" else shape_a[0]
        width_b = shape_b[1] if format == "csr" else shape_b[0]
        count_a = shape_a[0] if format == "csr" else shape_a[1]
        count_b = shape_b[0] if format == "csr" else shape_b[1]
        other_a, self.values_a, counts_a = _tables(a_lines, count_a, width_a)
        other_b, self.values_b, counts_b = _tables(b_lines, count_b, width_b)
        key = (format, width_b, other_a.shape, other_b.shape, other_a.tobytes(),
               other_b.tobytes())
        pattern = _PATTERNS.get(key, lambda: _Pattern(other_a, other_b, width_b, counts_a,
                                                      counts_b))
        self._key = key
        self.indptr, self.indices, self.positions = (pattern.indptr, pattern.indices,
                                                     pattern.positions)
        self.full_shape = (shape_a[0] * shape_b[0], shape_a[1] * shape_b[1])
        read_only(self.values_a, self.values_b)
        self.nbytes = pattern.nbytes + self.values_a.nbytes + self.values_b.nbytes

    def restricted(self, keep: np.ndarray) -> KroneckerLayout:
        """The layout of the principal submatrices ``[keep][:, keep]`` of its sums (square
        sums, ``keep`` sorted): the pattern's entries of the kept lines and other indices,
        renumbered, from the ``layout`` cache."""
        keep = np.asarray(keep, dtype=np.int64)
        key = (self._key, "restricted", keep.tobytes())
        pattern = _PATTERNS.get(key, lambda: _Restricted(self, keep))
        new = copy.copy(self)
        new.indptr, new.indices, new.positions = (pattern.indptr, pattern.indices,
                                                  pattern.positions)
        new.full_shape, new._key = (keep.size, keep.size), key
        new.nbytes = pattern.nbytes + self.values_a.nbytes + self.values_b.nbytes
        return new

    @classmethod
    def of(cls, pairs: Sequence[tuple[sp.spmatrix, sp.spmatrix]], format: str = "csr"
           ) -> KroneckerLayout:
        """The layout of ``pairs`` from the ``kronecker`` cache (keyed by the factors'
        formats, shapes and bytes), else made (and its pattern from the ``layout`` cache)."""
        key = (format, tuple((content(A), content(B)) for A, B in pairs))
        return _FACTORED.get(key, lambda: cls(pairs, format))

    def sums(self, sums: Sequence[Sequence[tuple[float, int]]],
             shape: tuple[int, int] | None = None) -> list[sp.spmatrix]:
        """``Σ_t w_t A_t ⊗ B_t`` for each list of ``(w_t, t)`` (``t``: a pair's index), on
        one copy of the layout's index arrays (theirs, not the layout's, to keep)."""
        indices, indptr = self.indices.copy(), self.indptr.copy()
        shape = self.full_shape if shape is None else shape
        flat_a = self.values_a.reshape(self.values_a.shape[0], -1)
        flat_b = self.values_b.reshape(self.values_b.shape[0], -1)
        product = np.empty((flat_a.shape[1], flat_b.shape[1]))    # (i e, k f), one for all
        out = []
        for terms in sums:
            if terms:
                weights = np.array([w for w, _ in terms], dtype=float)
                index = [t for _, t in terms]
                with np.errstate(over="ignore", invalid="ignore"):  # scales are checked later
                    # einsum, not BLAS: a second BLAS thread rarely finds a free core for
                    # so small a product (splinedeform.threads)
                    np.einsum("ti,tj->ij", flat_a[index] * weights[:, None], flat_b[index],
                              out=product)
                data = np.take(product.ravel(), self.positions)
            else:
                data = np.zeros(indices.size)
            out.append(compressed(self.cls, data, indices, indptr, shape))
        return out


def content(A: sp.spmatrix) -> tuple:
    """What identifies a sparse matrix: its format, shape and arrays' bytes."""
    if A.format not in ("csr", "csc"):
        A = A.tocsr()
    return (A.format, A.shape, A.has_canonical_format, A.data.tobytes(),
            A.indices.tobytes(), A.indptr.tobytes())


def _tables(entries: Sequence[tuple[np.ndarray, np.ndarray, np.ndarray]], count: int,
            width: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The union pattern of several matrices' ``(line, other, value)`` as a padded table of
    other indices ``(line, slot)`` (``-1``: padding), each matrix's values on it (``0``
    where it stores none), and the entries per line."""
    keys = [line * width + other for line, other, _ in entries]
    union = np.unique(np.concatenate(keys)) if len(keys) > 1 else keys[0]
    line = union // width
    counts = np.bincount(line, minlength=count)
    start = np.zeros(count + 1, dtype=np.int64)
    np.cumsum(counts, out=start[1:])
    slot = np.arange(union.size) - start[line]
    other = np.full((count, int(counts.max()) if count else 0), -1, dtype=np.int64)
    other[line, slot] = union % width
    values = np.zeros((len(entries),) + other.shape)
    for t, (key, (_, _, data)) in enumerate(zip(keys, entries)):
        at = np.searchsorted(union, key)
        values[t, line[at], slot[at]] = data
    return other, values, counts


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
    layout = KroneckerLayout.of(pairs, format)
    index, out = 0, []
    for terms in sums:
        out.append([(w, index + i) for i, (w, _, _) in enumerate(terms)])
        index += len(terms)
    return layout.sums(out, shape)


def kron(A: sp.spmatrix, B: sp.spmatrix, format: str = "csr") -> sp.spmatrix:
    """``A ⊗ B`` in CSR (or CSC) form, on the stored entries of both."""
    return kronecker_sum([(1.0, A, B)], format=format)


def principal_submatrices(matrices: Sequence[sp.spmatrix], keep: np.ndarray
                          ) -> list[sp.spmatrix]:
    """``A[keep][:, keep]`` of square compressed matrices sharing one canonical pattern
    (``keep`` sorted), selected together (:func:`_principal`)."""
    A = matrices[0]
    entries, indices, indptr = _principal(A.indptr, A.indices, A.shape[0],
                                          np.asarray(keep, dtype=np.int64))
    return [compressed(type(A), B.data[entries], indices, indptr, (keep.size, keep.size))
            for B in matrices]


def _principal(indptr: np.ndarray, indices: np.ndarray, n: int, keep: np.ndarray
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The principal submatrix ``keep`` (sorted) of a canonical ``n × n`` pattern: the
    stored entries of the kept lines whose other index is kept, their other indices
    renumbered (still sorted) and the new ``indptr``."""
    dtype = index_dtype(indices.size, n + 1)
    new = np.full(n, -1, dtype=np.int64)
    new[keep] = np.arange(keep.size)
    counts = np.diff(indptr)[keep]
    start = np.repeat(indptr[keep].astype(np.int64) - np.cumsum(counts) + counts, counts)
    entries = np.arange(start.size) + start               # the entries of the kept lines
    other = new[indices[entries]]
    stored = other >= 0
    line = np.repeat(np.arange(keep.size), counts)[stored]
    out_indptr = np.zeros(keep.size + 1, dtype=dtype)
    np.cumsum(np.bincount(line, minlength=keep.size), out=out_indptr[1:])
    return entries[stored], other[stored].astype(dtype), out_indptr
