"""Dense products of a tall matrix with a few columns, by BLAS ``dgemm`` directly.

``alpha op(a) op(b) + beta c`` with ``op(x) = x`` or ``xᵀ``. For the tall column-major
matrices of the modal solvers (a Krylov basis or the modes, ``n × p``) times a block of a
few columns, numpy's ``@`` took 2.5 times as long as ``dgemm`` at 128² (45 ms against
18 ms for ``16 129 × 800`` times ``800 × 16``, one BLAS thread). A C-ordered operand is
passed as the transpose of a Fortran-ordered one (no copy); other dtypes go to numpy.
:func:`selected_rows` tells whether a sparse map ``T`` only selects rows (its product a
gather).
"""

from __future__ import annotations

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
from numpy.typing import NDArray

Array = NDArray[np.float64]


def _fortran(x: Array, trans: int) -> tuple[Array, int]:
    """``x`` (or its transpose, with the flag flipped) as a Fortran-ordered operand."""
    if not x.flags.f_contiguous and x.flags.c_contiguous:
        return x.T, 1 - trans
    return x, trans


def gemm(alpha: float, a: Array, b: Array, beta: float = 0.0, c: Array | None = None,
         trans_a: int = 0) -> Array:
    """``alpha op(a) b + beta c`` (``op(a) = aᵀ`` with ``trans_a``); ``c`` is overwritten
    where it is Fortran-ordered float64 (use the returned array in any case)."""
    if a.dtype != np.float64 or b.dtype != np.float64 or \
            (c is not None and c.dtype != np.float64):
        product = alpha * ((a.T if trans_a else a) @ b)
        return product if c is None else beta * c + product
    a, trans_a = _fortran(a, trans_a)
    b, trans_b = _fortran(b, 0)
    if c is None:
        return sla.blas.dgemm(alpha, a, b, trans_a=trans_a, trans_b=trans_b)
    return sla.blas.dgemm(alpha, a, b, beta, c, trans_a=trans_a, trans_b=trans_b,
                          overwrite_c=1)


def selected_rows(T: sp.spmatrix) -> NDArray[np.int64] | None:
    """The row of each column of ``T`` when ``T`` is a selection (one entry 1 per column,
    distinct rows), else ``None``. Read from the compressed arrays as they are (CSR or CSC;
    others are converted): at 64² a conversion to CSC cost about 1 ms a call."""
    if not sp.issparse(T) or T.nnz != T.shape[1]:
        return None
    if T.format not in ("csr", "csc"):
        T = T.tocsr()
    if not np.all(T.data == 1.0):
        return None
    counts = np.diff(T.indptr)
    if T.format == "csc":
        if not np.all(counts == 1):
            return None
        rows = np.asarray(T.indices)
    else:
        columns = np.asarray(T.indices)
        if np.any(counts > 1) or np.bincount(columns, minlength=T.shape[1]).max(initial=0) != 1:
            return None
        rows = np.empty(T.shape[1], dtype=np.int64)     # distinct: one entry a row at most
        rows[columns] = np.repeat(np.arange(T.shape[0]), counts)
        return rows
    return rows if np.unique(rows).size == rows.size else None
