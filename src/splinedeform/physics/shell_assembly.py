"""Assembly of the shell's matrices cell by cell into a sparse pattern known in advance.

Every cell ``(a, b)`` of the tensor Gauss grid couples the ``(p_u+1)(p_v+1)`` functions
``b_i(u) b_j(v)`` that do not vanish on it, so the sparsity of ``K`` is the tensor product
of the 1-D couplings ``C_u[i, i'] = (b_i, b_i' share a cell)`` and ``C_v``, times the
``c × c`` coupling of the components. In CSR order (rows ``r = c(i n_v + j) + k``,
columns sorted) the entry ``(i, j, k; i', j', l)`` lies at::

    indptr[r] + pos_u[i, i'] · len_v[j] · c + pos_v[j, j'] · c + l

with ``pos`` the rank of ``i'`` among the columns of row ``i`` of ``C_u`` and ``len_v`` the
row lengths of ``C_v``: one integer formula, no sort of the ``(p+1)⁴`` entries of each
cell. Each cell's block is summed over its Gauss points by one batched matrix product
and scattered into the CSR data with :func:`numpy.bincount`; cells are taken a few rows at
a time so the work arrays stay a bounded size (:data:`CHUNK_ENTRIES`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray

Array = NDArray[np.float64]
Index = NDArray[np.int64]
#: cells per chunk are chosen so a chunk's work arrays hold about this many floats
CHUNK_ENTRIES = 4_000_000


def coupling(cell_index: Index, size: int) -> tuple[Index, Index, Index]:
    """1-D coupling of a basis: ``(pos (size, size), lengths (size,), columns)``.

    ``cell_index (cells, p+1)`` lists the functions of each cell; ``pos[i, i']`` is the rank
    of ``i'`` among the (sorted) functions sharing a cell with ``i`` (``-1`` if none),
    ``columns`` those functions row after row.
    """
    C = np.zeros((size, size), dtype=bool)
    C[cell_index[:, :, None], cell_index[:, None, :]] = True
    pos = np.where(C, np.cumsum(C, axis=1) - 1, -1)
    return pos, C.sum(axis=1), np.nonzero(C)[1]


@dataclass(frozen=True)
class Pattern:
    """CSR structure of a tensor-product shell matrix with ``components`` unknowns per point."""

    pos_u: Index
    len_u: Index
    cols_u: Index
    pos_v: Index
    len_v: Index
    cols_v: Index
    components: int

    @classmethod
    def of(cls, cells_u: Index, cells_v: Index, n_u: int, n_v: int, components: int
           ) -> Pattern:
        """Pattern of the cells' functions ``cells_u (c_u, p_u+1)``, ``cells_v (c_v, p_v+1)``."""
        return cls(*coupling(cells_u, n_u), *coupling(cells_v, n_v), components)

    @property
    def size(self) -> int:
        return self.len_u.size * self.len_v.size * self.components

    def indptr(self) -> Index:
        c = self.components
        lengths = np.repeat((self.len_u[:, None] * self.len_v[None, :]).ravel() * c, c)
        return np.r_[0, np.cumsum(lengths)]

    def indices(self) -> Index:
        """Column of every stored entry, row after row, sorted within each row."""
        n_v, c = self.len_v.size, self.components
        iu, ipu = np.nonzero(self.pos_u >= 0)                # couplings (i, i') and (j, j')
        jv, jpv = np.nonzero(self.pos_v >= 0)
        k = np.arange(c)
        where = self._entry(iu[:, None], jv[None, :], ipu[:, None], jpv[None, :])
        cols = (ipu[:, None] * n_v + jpv[None, :])[..., None, None] * c + k[None, :]
        out = np.empty(self.indptr()[-1], dtype=np.int64)
        out[where.ravel()] = np.broadcast_to(cols, where.shape).ravel()
        return out

    def _entry(self, i: Index, j: Index, ip: Index, jp: Index) -> Index:
        """Data index of ``(k, i, j; l, i', j')`` at ``i, j, i', j'``, ``(..., c, c)``."""
        c, n_v = self.components, self.len_v.size
        k = np.arange(c)
        rowlen = (self.len_u[i] * self.len_v[j] * c)[..., None, None]
        start = self.indptr()[(i * n_v + j) * c][..., None, None]
        within = (self.pos_u[i, ip] * self.len_v[j] * c + self.pos_v[j, jp] * c)[..., None, None]
        return start + k[:, None] * rowlen + within + k[None, :]

    def positions(self, cells_u: Index, cells_v: Index) -> Index:
        """Data index of every block entry of the cells ``cells_u × cells_v``.

        ``cells_u (A, p_u+1)``, ``cells_v (B, p_v+1)``; local unknowns are ordered
        ``(component, k_u, k_v)``; returns ``(A, B, m, m)`` with ``m = c (p_u+1)(p_v+1)``.
        """
        iu, iv = cells_u[:, None, :, None], cells_v[None, :, None, :]   # (A, B, ku, kv)
        entry = self._entry(iu[..., None, None], iv[..., None, None],
                            iu[:, :, None, None], iv[:, :, None, None])
        # entry (A, B, ku, kv, lu, lv, k, l) → (A, B, (k, ku, kv), (l, lu, lv))
        entry = entry.transpose(0, 1, 6, 2, 3, 7, 4, 5)
        m = self.components * cells_u.shape[1] * cells_v.shape[1]
        return entry.reshape(entry.shape[0], entry.shape[1], m, m)


def assemble_cells(pattern: Pattern, cells_u: Index, cells_v: Index,
                   blocks: Callable[[slice], Array]) -> sp.csr_matrix:
    """Sum the symmetric cell blocks ``blocks(rows)`` (``(A, B, m, m)``) into ``pattern``.

    ``blocks`` is called on slices of cell rows in u, a bounded number of cells at a time;
    the sum is symmetrised once, ``½(K + Kᵀ)`` on the CSR data (the same as symmetrising
    each block, ``Σ ½(Kₑ + Kₑᵀ)``, up to the order of the additions).
    """
    m = pattern.components * cells_u.shape[1] * cells_v.shape[1]
    indptr, indices = pattern.indptr(), pattern.indices()
    data = np.zeros(indptr[-1])
    step = max(1, CHUNK_ENTRIES // max(1, cells_v.shape[0] * m * m * 4))
    for a in range(0, cells_u.shape[0], step):
        rows = slice(a, min(a + step, cells_u.shape[0]))
        where = pattern.positions(cells_u[rows], cells_v).ravel()
        # a chunk's rows are a contiguous stretch of the data: sum into that stretch only
        lo, hi = int(where.min()), int(where.max()) + 1
        data[lo:hi] += np.bincount(where - lo, blocks(rows).ravel(), minlength=hi - lo)
    # ½(K + Kᵀ) entry by entry: the pattern is symmetric, so K's transpose has the same
    # structure and its data are K's read at the transposed positions (exactly symmetric)
    data = 0.5 * (data + data[transposed(indptr, indices)])
    return sp.csr_matrix((data, indices, indptr), shape=(pattern.size,) * 2)


def transposed(indptr: Index, indices: Index) -> Index:
    """Position of entry ``(j, i)`` for every stored ``(i, j)`` of a symmetric CSR pattern."""
    n = indptr.size - 1
    order = sp.csr_matrix((np.arange(1, indices.size + 1), indices, indptr),
                          shape=(n, n)).T.tocsr()            # 1-based: no stored zero
    order.sort_indices()
    if order.nnz != indices.size or not np.array_equal(order.indices, indices):
        raise ValueError("the pattern is not symmetric")
    return order.data - 1
