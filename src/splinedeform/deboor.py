"""The triangle of the Cox–de Boor recurrence for many parameters at once.

On a non-empty knot span ``t_μ <= x < t_{μ+1}`` of a degree-``n`` knot vector the
``n + 1`` B-splines not vanishing at ``x`` are ``N_{μ-n+r, n}``, ``r = 0..n``. With
``left_k = x - t_{μ+1-k}`` and ``right_k = t_{μ+k} - x`` (``k = 1..n``) they follow from

.. math:: N_{i,p}(x) = \\frac{x - t_i}{t_{i+p} - t_i} N_{i,p-1}(x)
          + \\frac{t_{i+p+1} - x}{t_{i+p+1} - t_{i+1}} N_{i+1,p-1}(x)

arranged as a triangle over ``p = 0..n`` (Piegl & Tiller, *The NURBS Book*, algorithm
A2.2), and their derivatives from the same triangle (A2.3, from
``D N_{i,p} = p N_{i,p-1}/(t_{i+p}-t_i) - p N_{i+1,p-1}/(t_{i+p+1}-t_{i+1})``).
Every denominator is a knot difference ``t_{μ+r+1} - t_{μ+1-j+r}`` spanning
``[t_μ, t_{μ+1}]``, so it is positive on a non-empty span: no ``0/0`` convention is needed.

Here the recurrence runs over arrays: each quantity is a vector over a block of
parameters, and the Python loops run over the degree only (``O(n²)`` vector operations
per block). Blocks of :data:`BLOCK` parameters keep every temporary small: the
allocator then reuses memory instead of mapping fresh pages for each of the ``O(n²)``
temporaries, which made one long vector ten times slower than the same work in blocks.
"""

from __future__ import annotations

from math import factorial

import numpy as np
from numpy.typing import NDArray

Array = NDArray[np.float64]

BLOCK = 1024
"""Parameters per block of the vectorised evaluations (temporaries of at most 32 KiB)."""


def triangle(left: Array, right: Array, degree: int, max_derivative: int) -> Array:
    """``D^j N_{μ-n+r, n}(x)`` for ``j = 0..max_derivative``, ``r = 0..n``, all parameters.

    Parameters
    ----------
    left, right : ndarray, shape ``(n, N)``
        ``left[k-1] = x - t_{μ+1-k}`` and ``right[k-1] = t_{μ+k} - x`` for ``k = 1..n``,
        each parameter on its own span ``μ``.
    degree : int
        ``n >= 1``.
    max_derivative : int
        Highest derivative order, ``0 <= max_derivative <= n``.

    Returns
    -------
    ndarray, shape ``(max_derivative + 1, n + 1, N)``
    """
    N = left.shape[1]
    out = np.empty((max_derivative + 1, degree + 1, N))
    for start in range(0, N, BLOCK):
        block = slice(start, start + BLOCK)
        _triangle_block(left[:, block], right[:, block], degree, max_derivative, out[:, :, block])
    return out


def _triangle_block(left: Array, right: Array, degree: int, max_derivative: int,
                    out: Array) -> None:
    """:func:`triangle` on one block of parameters, written into ``out``."""
    n, jmax = degree, max_derivative
    N = left.shape[1]
    # ndu[r][j] (r <= j): N_{μ-j+r, j}; ndu[j][r] (r < j): the knot difference right_{r+1} + left_{j-r}
    ndu: list[list] = [[None] * (n + 1) for _ in range(n + 1)]
    ndu[0][0] = np.ones(N)
    for j in range(1, n + 1):
        saved = 0.0
        for r in range(j):
            ndu[j][r] = right[r] + left[j - r - 1]
            temp = ndu[r][j - 1] / ndu[j][r]
            ndu[r][j] = saved + right[r] * temp
            saved = left[j - r - 1] * temp
        ndu[j][j] = saved
    for r in range(n + 1):
        out[0, r] = ndu[r][n]
    for r in range(n + 1):
        a_prev: list = [1.0]
        for k in range(1, jmax + 1):
            a_new: list = [None] * (k + 1)
            d: Array | float = 0.0
            rk, pk = r - k, n - k
            if r >= k:
                a_new[0] = a_prev[0] / ndu[pk + 1][rk]
                d = a_new[0] * ndu[rk][pk]
            first = 1 if rk >= -1 else -rk
            last = k - 1 if r - 1 <= pk else n - r
            for j in range(first, last + 1):
                a_new[j] = (a_prev[j] - a_prev[j - 1]) / ndu[pk + 1][rk + j]
                d = d + a_new[j] * ndu[rk + j][pk]
            if r <= pk:
                a_new[k] = -a_prev[k - 1] / ndu[pk + 1][r]
                d = d + a_new[k] * ndu[r][pk]
            out[k, r] = d
            a_prev = a_new
    for k in range(1, jmax + 1):
        out[k] *= factorial(n) // factorial(n - k)

