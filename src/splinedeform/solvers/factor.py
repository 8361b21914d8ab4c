"""One symmetric factorisation of a constrained stiffness (or any SPD) matrix.

Once constrained, ``K_r`` is symmetric positive definite, so ``K_r = Lᵀ L`` (Cholesky) and
every solve is two triangular sweeps. Which factorisation is fastest was measured on
the bench plate (docs/cost.md, "where the time goes"):

``"banded"``
    LAPACK's band Cholesky (``dpbtrf``, :func:`scipy.linalg.cholesky_banded`) in the
    natural order of the free coordinates. The Kronecker ordering of a tensor-product
    net keeps the half bandwidth at ``b = n (m_v + 1)`` for degree ``n`` and ``m_v`` free
    coordinates along v, so the cost is ``N b²`` flops of dense, blocked level-3 BLAS and
    ``N (b + 1)`` numbers of storage. Chosen while that storage is at most
    :data:`BAND_BYTES`.
``"superlu"``
    SuperLU (:func:`scipy.sparse.linalg.splu`) with the symmetric options: the minimum
    degree ordering of ``Kᵀ + K`` (``MMD_AT_PLUS_A``), no threshold pivoting
    (``diag_pivot_thresh = 0``: the diagonal of an SPD matrix is a stable pivot) and
    ``SymmetricMode``. The default column ordering (``COLAMD``) ignores the symmetry and
    fills in several times more. The fallback for any matrix.
``"cholmod"``
    CHOLMOD's supernodal Cholesky (scikit-sparse, not a dependency: it has no wheel and
    builds only against a SuiteSparse installation); used by ``"auto"`` only where it is
    installed and the band is too wide.

``factorise(K)`` returns an object with ``solve(b)`` for ``b`` of shape ``(N,)`` or
``(N, k)`` and the name of the method used.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from numpy.typing import NDArray

from ..errors import InputError

Array = NDArray[np.float64]

METHODS = ("auto", "banded", "superlu", "cholmod")

BAND_BYTES = 128 * 2**20
"""Largest band storage ``8 N (b + 1)`` bytes for which ``"auto"`` takes the band Cholesky."""
BAND_FLOPS = 1e10
"""Largest work ``N b²`` of :func:`band_cholesky` (a few seconds): a matrix whose band
is wide because of its ordering goes to the sparse LU instead (128² cubic: 2.5·10⁹)."""


@dataclass(frozen=True)
class Factorisation:
    """A factorised matrix: ``solve(b)`` returns ``K⁻¹ b``; ``method`` names how."""

    method: str
    solve: Callable[[Array], Array]


def half_bandwidth(K: sp.spmatrix) -> int:
    """``max |i - j|`` over the stored entries of ``K`` (0 for a diagonal or empty matrix).

    From a compressed matrix with sorted indices only the first and last index of each
    column (row) are read, ``O(N)`` instead of ``O(nnz)`` (at 64² 0.05 ms against 1 ms
    for the coordinates of all 184 041 entries)."""
    if sp.issparse(K) and K.format in ("csc", "csr") and K.has_sorted_indices:
        nonempty = np.flatnonzero(np.diff(K.indptr))
        if not nonempty.size:
            return 0
        first = K.indices[K.indptr[nonempty]]
        last = K.indices[K.indptr[nonempty + 1] - 1]
        return int(max(np.max(nonempty - first), np.max(last - nonempty)))
    rows, columns, _ = _entries(K)
    return int(np.abs(rows - columns).max()) if rows.size else 0


def _entries(K: sp.spmatrix) -> tuple[NDArray[np.int64], NDArray[np.int64], Array]:
    """Row, column and value of every stored entry of ``K``, column by column (from its
    compressed columns: no coordinate copy of the matrix)."""
    K = K if sp.isspmatrix_csc(K) or isinstance(K, sp.csc_array) else sp.csc_matrix(K)
    columns = np.repeat(np.arange(K.shape[1]), np.diff(K.indptr))
    return K.indices, columns, K.data


def factorise(K: sp.spmatrix, method: str = "auto") -> Factorisation:
    """Factorise the symmetric matrix ``K`` once.

    Parameters
    ----------
    K : sparse matrix, shape ``(N, N)``
        Symmetric; positive definite for the Cholesky methods.
    method : {"auto", "banded", "superlu", "cholmod"}
        ``"auto"``: the band Cholesky while its storage is at most :data:`BAND_BYTES`
        and its work ``N b²`` at most :data:`BAND_FLOPS`,
        else CHOLMOD where installed, else SuperLU. A Cholesky method that finds ``K``
        not positive definite falls back to SuperLU (which then solves an indefinite
        but regular ``K`` or raises ``RuntimeError`` for a singular one, as ``splu`` does).

    Returns
    -------
    Factorisation
    """
    if method not in METHODS:
        raise InputError(f"factorisation method must be one of {METHODS}, got {method!r}")
    if K.shape[0] != K.shape[1]:
        raise InputError(f"a factorised matrix must be square, got shape {K.shape}")
    if method == "auto":
        n, b = K.shape[0], half_bandwidth(K)
        if 8 * n * (b + 1) <= BAND_BYTES and n * b * b <= BAND_FLOPS:
            method = "banded"
        else:
            method = "cholmod" if _cholmod() is not None else "superlu"
    try:
        if method == "banded":
            return _banded(K)
        if method == "cholmod":
            module = _cholmod()
            if module is None:
                raise InputError("factorisation 'cholmod' needs scikit-sparse, which is not "
                                 "installed (it builds from source against SuiteSparse: e.g. "
                                 "Debian's libsuitesparse-dev with scikit-sparse 0.4.16)")
            factor = module.cholesky(sp.csc_matrix(K))
            return Factorisation("cholmod", factor)
    except np.linalg.LinAlgError:
        pass                                   # not positive definite: the general LU below
    except Exception as error:                 # CHOLMOD's NotPositiveDefiniteError
        if type(error).__name__ != "CholmodNotPositiveDefiniteError":
            raise
    return _superlu(K)


def band_cholesky(K: sp.spmatrix) -> Factorisation | None:
    """The band Cholesky of ``K`` where its storage ``8 N (b + 1)`` fits :data:`BAND_BYTES`
    and ``K`` is positive definite; ``None`` otherwise (the caller's own fallback then).

    The first choice of every factorisation of a stiffness in the Kronecker order (the
    static solve, the shift-invert Lanczos of :mod:`.sparse_eigen`, the sparse bases of
    :mod:`.modal_basis`): at 64² it factorises in 0.023 s against SuperLU's 0.057 s and
    solves a vector in 0.43 ms against 0.84 ms in blocks of 8, 1.7 ms alone (CPU, one run,
    load average 5).
    """
    n, b = K.shape[0], half_bandwidth(K)
    if 8 * n * (b + 1) > BAND_BYTES or n * b * b > BAND_FLOPS:
        return None
    try:
        return _banded(K)
    except np.linalg.LinAlgError:
        return None


def _banded(K: sp.spmatrix) -> Factorisation:
    """LAPACK band Cholesky ``K = Uᵀ U`` on the upper band (``dpbtrf`` / ``dpbtrs``).

    The band is written straight from the compressed columns into Fortran-ordered storage
    ``ab[b + i - j, j] = K_ij`` (``i <= j``), the layout LAPACK reads, so that the wrapper
    copies nothing before ``dpbtrf`` factorises it in place (at 64² the copy of a C-ordered
    band cost a quarter of the factorisation).
    """
    U = sla.cholesky_banded(band_storage(K), overwrite_ab=True, lower=False,
                            check_finite=False)

    def solve(rhs: Array) -> Array:
        return sla.cho_solve_banded((U, False), np.asarray(rhs, dtype=float),
                                    check_finite=False)

    return Factorisation("banded", solve)


def band_storage(K: sp.spmatrix, lower: bool = False) -> Array:
    """One triangle of a symmetric ``K`` in LAPACK's band storage, Fortran order:
    ``ab[b + i − j, j] = K_ij`` for ``i ≤ j`` (upper), ``ab[i − j, j] = K_ij`` for ``i ≥ j``
    (``lower``), ``b`` the half bandwidth of that triangle."""
    rows, columns, values = _entries(K)
    keep = rows >= columns if lower else rows <= columns
    rows, columns, values = rows[keep], columns[keep], values[keep]
    offset = rows - columns if lower else columns - rows
    b = int(offset.max()) if rows.size else 0
    band = np.zeros((b + 1, K.shape[0]), order="F")
    band[offset if lower else b - offset, columns] = values
    return band


def _superlu(K: sp.spmatrix) -> Factorisation:
    """SuperLU with the symmetric ordering ``MMD_AT_PLUS_A`` and diagonal pivots."""
    lu = spla.splu(sp.csc_matrix(K), permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                   options={"SymmetricMode": True})
    return Factorisation("superlu", lu.solve)


def _cholmod():  # pragma: no cover - only with the optional extra
    try:
        from sksparse import cholmod
    except ImportError:
        return None
    return cholmod
