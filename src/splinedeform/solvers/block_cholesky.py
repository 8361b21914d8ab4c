"""Cholesky factor of a banded SPD matrix as a block bidiagonal one: level-3 solves.

A symmetric positive definite ``A`` of half bandwidth ``b`` (a stiffness in the Kronecker
order of a tensor-product net, :mod:`.factor`) is block tridiagonal once cut into
consecutive blocks of ``w ≥ b`` unknowns, and so is its Cholesky factor ``A = L Lᵀ``
block bidiagonal:

.. math:: L_{ii} L_{ii}^T = A_{ii} − C_{i−1} C_{i−1}^T, \\qquad
          C_i = A_{i+1,i} L_{ii}^{−T},

(``C_i = L_{i+1,i}``, upper triangular as ``A_{i+1,i}`` is). A solve of ``r`` right-hand
sides is then two sweeps over the blocks, each two triangular products with ``r`` columns
(the inverses ``L_ii⁻¹`` are kept: a triangular product runs at twice the rate of a
triangular solve with a few dozen columns),

.. math:: y_i = L_{ii}^{−1} (f_i − C_{i−1} y_{i−1}), \\qquad
          x_i = L_{ii}^{−T} (y_i − C_i^T x_{i+1}),

``2 N w r`` flops per sweep in matrix–matrix products (level-3 BLAS). What it is for: the
block shift-invert Lanczos (:mod:`.sparse_eigen`) solves a block of vectors at a time, and
LAPACK's band solve (``dpbtrs``) takes the right-hand sides one by one, reading the whole
band for each (memory-bound). Measured on the bench plate, one BLAS thread
(benchmarks/results.md): at 128² (``N = 16 129``, ``b = 384``) the band solve took
8.1 ms a vector, these sweeps 2.2 ms in blocks of 16 (:data:`CACHED_BAND`), the two
solutions within 1.3e-12 of each other relative to their size. The factor keeps ``N w``
numbers, packed (:class:`BlockCholesky`): as many as the band's.
"""

from __future__ import annotations

import functools

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
from numpy.typing import NDArray

from .factor import band_storage, half_bandwidth

Array = NDArray[np.float64]
BLOCK_BYTES = 256 * 2**20
"""Largest ``16 N w`` bytes for a block factor (128² cubic: 99 MB); the packed factor keeps
half that, ``8 N w`` (the limit was set when it kept all of it)."""
CACHED_BAND = 16 * 2**20
"""Band storage (bytes) up to which the band solve is kept: at 64² (6 MB) it solved 0.42 ms
a vector in blocks of 8 against these sweeps' 0.79 ms, at 128² (50 MB) 8.1 ms against 3.8
(blocks of 8), 2.2 (16) and 1.5 (32) (CPU time, one BLAS thread, best of five)."""
SMALLEST_BLOCK = 64
FEW = 4
"""Blocks are at least this wide (fewer, larger products where the band is narrow)."""


class BlockCholesky:
    """``A = L Lᵀ`` with ``L`` block bidiagonal (module docstring); :meth:`solve`.

    Stored packed, one ``w × w`` array a block row: ``L_ii⁻¹ = Δ_i U_i`` with ``Δ_i`` its
    diagonal and ``U_i`` unit lower triangular, so ``L_ii⁻¹ x = Δ_i (U_i x)`` and
    ``L_ii^{−T} x = U_iᵀ (Δ_i x)`` (a triangular product that takes the diagonal as ones);
    ``U_i``'s strict lower triangle and the upper triangle of ``C_{i−1}`` share block
    ``i``'s array. Each sweep reads that array twice in a row (the second time from
    cache), so the factor's memory is read once a sweep: ``N w`` numbers instead of
    ``2 N w`` (at 128² a solve of 16 columns took 18 ms against 20, of 2 columns 6.1 ms
    against 7.0, one BLAS thread, the machine possibly busy). A short last block keeps
    its rectangular ``C`` apart.

    Parameters
    ----------
    A : sparse symmetric positive definite, half bandwidth ``b``.
    width : block size ``w ≥ b`` (default ``max(b, SMALLEST_BLOCK)``).

    Raises
    ------
    numpy.linalg.LinAlgError
        Where a diagonal block is not positive definite (nor then is ``A``).
    """

    method = "block"

    def __init__(self, A: sp.spmatrix, width: int | None = None):
        n = A.shape[0]
        b = half_bandwidth(A)
        w = max(b, 1, min(SMALLEST_BLOCK, n) if width is None else int(width))
        if width is not None and w != width:
            raise ValueError(f"block width {width} is below the half bandwidth {b}")
        self.n = n
        self.edges = np.append(np.arange(0, n, w), n)
        # LAPACK's band Cholesky (dpbtrf) does the recurrence of the module docstring, the
        # same factor by uniqueness; the blocks are read out of its band and the diagonal
        # ones inverted (dtrtri). At 128² 0.45–0.50 s of processor time against 0.50–0.65 s
        # for the recurrence written with dsyrk, dpotrf, dtrtri and dtrmm a block (five
        # runs each, one BLAS thread); of the 0.48 s, dpbtrf takes 0.12 and dtrtri 0.14
        L = sla.cholesky_banded(band_storage(A, lower=True), overwrite_ab=True, lower=True,
                                check_finite=False)
        self.packed: list[Array] = []     # U_i below the diagonal, C_{i−1} on and above
        self.diagonal: list[Array] = []   # Δ_i, as a column
        self.tail: Array | None = None    # C of a short last block (rectangular)
        previous: Array | None = None
        for i, (lo, hi) in enumerate(zip(self.edges[:-1], self.edges[1:])):
            inverse, info = sla.lapack.dtrtri(_band_block(L, lo, 0, hi - lo, hi - lo),
                                              lower=1, overwrite_c=1)
            if info:
                raise np.linalg.LinAlgError("a diagonal block of the factor is singular")
            d = inverse.diagonal().copy()
            if previous is None or previous.shape[0] != previous.shape[1]:
                self.tail = previous
                packed = inverse                                # no C above the diagonal
            else:
                packed = previous                               # C_{i−1}: upper triangular
            if hi < n:
                # C_i = L_{i+1,i}: upper triangular (trapezoidal for a short last block)
                previous = _band_block(L, lo, hi - lo, self.edges[i + 2] - hi, hi - lo)
            # U_i = Δ_i⁻¹ L_ii⁻¹ below the diagonal
            np.divide(inverse, d[:, None], out=packed, where=_strictly_lower(hi - lo))
            self.packed.append(packed)
            self.diagonal.append(d[:, None])

    def solve(self, rhs: Array) -> Array:
        """``A⁻¹ rhs`` for ``rhs`` of shape ``(N,)`` or ``(N, r)``, in Fortran order.

        Every product is a triangular one (``dtrmm`` from the left) on the block rows
        ``x_i`` of the column-major ``x``: the modal solvers' blocks of vectors are
        column-major, and a transposing copy of one (``16 129 × 16``) took about as long as
        a tenth of the solve.
        """
        f = np.asarray(rhs, dtype=float)
        x = np.array(f.reshape(self.n, -1), order="F")
        edges, P, d, tail = self.edges, self.packed, self.diagonal, self.tail
        blocks = len(P)
        for i in range(blocks):                             # L y = f
            lo, hi = edges[i], edges[i + 1]
            if i:
                before = x[edges[i - 1]:lo]
                x[lo:hi] -= tail @ before if i == blocks - 1 and tail is not None else \
                    _times(P[i], before, upper=True, transpose=False)
            np.multiply(d[i], _times(P[i], x[lo:hi], upper=False, transpose=False),
                        out=x[lo:hi])
        for i in range(blocks - 1, -1, -1):                 # Lᵀ x = y
            lo, hi = edges[i], edges[i + 1]
            if i < blocks - 1:
                after = x[hi:edges[i + 2]]
                x[lo:hi] -= tail.T @ after if i == blocks - 2 and tail is not None else \
                    _times(P[i + 1], after, upper=True, transpose=True)
            x[lo:hi] = _times(P[i], d[i] * x[lo:hi], upper=False, transpose=True)
        return x.reshape(f.shape, order="F")


def _band_block(L: Array, column: int, shift: int, rows: int, columns: int) -> Array:
    """The dense ``rows × columns`` block ``D[r, c] = L_{column + shift + r, column + c}`` of
    a lower band factor ``L`` (LAPACK storage ``ab[i − j, j] = L_ij``, Fortran order, half
    bandwidth ``b``), in Fortran order, zero outside the band.

    In that storage ``ab[shift + r − c, column + c]`` lies at ``(b + 1) column + shift + r
    + b c`` of the column-major buffer: the block is a strided view with strides
    ``(1, b)`` elements, copied, and the entries with ``shift + r − c`` outside ``[0, b]``
    (read from neighbouring columns) set to zero. The last element read,
    ``(b + 1) column + shift + rows − 1 + b (columns − 1)``, lies inside the buffer for the
    two blocks taken: a diagonal one (``shift = 0``, ``rows = columns``, ``column + rows <=
    N``) and the one below it (``shift = columns``, ``column + shift + rows <= N``).
    """
    b = L.shape[0] - 1
    flat = L.reshape(-1, order="F")
    step = flat.strides[0]
    view = np.lib.stride_tricks.as_strided(flat[(b + 1) * column + shift:],
                                           shape=(rows, columns), strides=(step, b * step),
                                           writeable=False)
    block = np.array(view, order="F")
    block[_outside(b, shift, rows, columns)] = 0.0
    return block


@functools.lru_cache(maxsize=8)
def _outside(b: int, shift: int, rows: int, columns: int) -> NDArray[np.bool_]:
    """Mask of a block's entries outside the band (:func:`_band_block`), the same for
    every block of a factor but the last: made once."""
    offset = shift + np.arange(rows)[:, None] - np.arange(columns)[None, :]
    return (offset < 0) | (offset > b)


@functools.lru_cache(maxsize=4)
def _strictly_lower(size: int) -> NDArray[np.bool_]:
    return np.tri(size, k=-1, dtype=bool)


def _times(T: Array, x: Array, upper: bool, transpose: bool) -> Array:
    """``T x`` (or ``Tᵀ x``) for ``x`` of shape ``(k, r)`` and ``T`` the upper triangle of
    a packed block (``upper``) or its unit lower triangle (the diagonal taken as ones), by
    ``dtrmm`` from the left; fewer than :data:`FEW` columns by ``dtrmv`` column by column
    (``dtrmm`` on one column took ten times as long; numpy's product on two columns twice
    as long as two ``dtrmv``: 31 against 15 ms for the 84 blocks of a 128² factor)."""
    lower, unit, trans = (0, 0, int(transpose)) if upper else (1, 1, int(transpose))
    if x.shape[1] < FEW:
        out = np.empty(x.shape, order="F")
        for c in range(x.shape[1]):
            out[:, c] = sla.blas.dtrmv(T, x[:, c], lower=lower, trans=trans, diag=unit)
        return out
    return sla.blas.dtrmm(1.0, T, x, side=0, lower=lower, trans_a=trans, diag=unit)


def block_cholesky(A: sp.spmatrix) -> BlockCholesky | None:
    """The :class:`BlockCholesky` of ``A`` where the band storage ``8 N (b + 1)`` exceeds
    :data:`CACHED_BAND` (below, LAPACK's band solve reads a band that stays in cache and is
    as fast), the block factor's fits :data:`BLOCK_BYTES` and ``A`` is positive definite;
    ``None`` otherwise (the caller's fallback then)."""
    n, b = A.shape[0], half_bandwidth(A)
    w = max(b, min(SMALLEST_BLOCK, n))
    if 8 * n * (b + 1) <= CACHED_BAND or 16 * n * w > BLOCK_BYTES:
        return None
    try:
        return BlockCholesky(A)
    except np.linalg.LinAlgError:
        return None
