"""Products ``A @ R`` with a collocation matrix ``A_{i, index[i, r]} = values[i, r]``.

A row of ``A`` holds the ``n + 1`` B-splines not vanishing at parameter ``x_i``, so
``(A R)_i = Σ_r values[i, r] R_{index[i, r]}``: ``n + 1`` scaled rows of ``R`` per
parameter. Which way is fastest depends on the size (measured on a 64²-cell cubic net,
benchmarks/bench_evaluate.py):

* small products gather the rows and contract them (a few numpy calls: no matrix is built);
* large products over sorted parameters (a tensor grid's) are dense products of blocks:
  :data:`BLOCK_ROWS` consecutive parameters touch a window of a few consecutive rows of
  ``R``, so each block is one small dense matrix times a contiguous slice of ``R``, done
  by BLAS at several times the speed of a sparse product's scattered updates;
* anything else is scipy's sparse product on ``A`` built from its CSR arrays
  (``csr_array``, without the ``np.matrix`` layer of ``csr_matrix``).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray

from .threads import library_threads

Array = NDArray[np.float64]

GATHER_LIMIT = 16384
"""Most numbers ``N (n+1) w`` :func:`collocate` gathers instead of building a matrix."""
BLOCKED_LIMIT = 2**20
"""Fewest numbers ``N w`` of a result that :func:`collocate` computes by dense blocks
(below it the block loop's set-up costs more than it saves)."""
BLOCK_ROWS = 16
"""Parameters per dense block (measured fastest of 8 … 128 at 1000² samples)."""


def collocate(index: NDArray[np.int64], values: Array, rows: Array) -> Array:
    """``A @ rows`` for ``A_{i, index[i, r]} = values[i, r]``; shape ``(N, w)``.

    Parameters
    ----------
    index, values : ndarray, shape ``(N, n + 1)``
        The functions not vanishing at each parameter and their values.
    rows : ndarray, shape ``(size, w)``
    """
    count, width = index.shape
    if index.size * rows.shape[1] <= GATHER_LIMIT:
        return np.matmul(values[:, None, :], rows[index])[:, 0]
    first = index[:, 0]
    if (count * rows.shape[1] >= BLOCKED_LIMIT and np.all(index[:, -1] - first == width - 1)
            and np.all(first[1:] >= first[:-1])):
        return _blocked(index, values, rows)
    indptr = np.arange(0, count * width + 1, width)
    A = sp.csr_array((values.ravel(), index.ravel(), indptr), shape=(count, rows.shape[0]))
    return A @ rows


def _blocked(index: NDArray[np.int64], values: Array, rows: Array) -> Array:
    """:func:`collocate` for non-decreasing consecutive indices, by dense blocks.

    Block ``b`` (parameters ``16 b … 16 b + 15``) touches rows ``lo_b … lo_b + s - 1`` of
    ``rows`` (``s`` the widest window of any block): ``Y_b = D_b rows[lo_b : lo_b + s]``
    with ``D_b`` the block's ``16 × s`` part of ``A``.
    """
    count, width = index.shape
    blocks = -(-count // BLOCK_ROWS)
    pad = blocks * BLOCK_ROWS - count
    if pad:                      # the last block padded with copies of the last parameter
        index = np.concatenate([index, np.repeat(index[-1:], pad, axis=0)])
        values = np.concatenate([values, np.zeros((pad, width))])
    index = index.reshape(blocks, BLOCK_ROWS, width)
    low = index[:, 0, 0]
    span = int((index[:, -1, -1] - low).max()) + 1
    low = np.minimum(low, rows.shape[0] - span)        # every window inside ``rows``
    dense = np.zeros((blocks, BLOCK_ROWS, span))
    block, row = np.indices((blocks, BLOCK_ROWS))
    # each block's values at their columns in its window (one scatter for all blocks)
    dense[block[..., None], row[..., None], index - low[:, None, None]] = \
        values.reshape(blocks, BLOCK_ROWS, width)
    out = np.empty((blocks * BLOCK_ROWS, rows.shape[1]))
    with library_threads():
        for b in range(blocks):
            np.matmul(dense[b], rows[low[b]:low[b] + span],
                      out=out[b * BLOCK_ROWS:(b + 1) * BLOCK_ROWS])
    return out[:count]
