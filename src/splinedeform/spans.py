"""The non-zero B-splines of each knot span in Bernstein (Bézier) form.

On a non-empty span ``[t_μ, t_{μ+1}]`` of width ``w`` every B-spline of degree ``n`` is a
polynomial; in the local parameter ``s = (x - t_μ)/w ∈ [0, 1]`` it has Bézier coefficients
``β_{r,k}`` (``r = 0..n`` the functions ``N_{μ-n+r}``, ``k = 0..n``):

.. math:: N_{μ-n+r}(x) = \\sum_k β_{r,k} B_{k,n}(s), \\qquad
          B_{k,n}(s) = \\binom{n}{k} s^k (1-s)^{n-k}.

The ``β`` lie in ``[0, 1]`` (they come from knot insertion, a convex process) and the
Bernstein polynomials are non-negative, so the sum is evaluated without cancellation.
They are found once per basis from the derivatives at the span's ends (the
Cox–de Boor triangle, :mod:`splinedeform.deboor`), by
``β_{r,k} = Σ_{j<=k} C(k,j) (n-j)!/n! w^j D^j N_{μ-n+r}(t_μ)``, the inverse of
``D^j p(0) = n!/(n-j)! Δ^j β_0`` for ``p(s) = Σ_k β_k B_{k,n}(s)``, for ``k <= n/2``, and
the mirror formula ``β_{r,n-k} = Σ_{j<=k} C(k,j) (n-j)!/n! (-w)^j D^j N_{μ-n+r}(t_{μ+1})``
for the others: the end values ``β_{r,0}`` and ``β_{r,n}`` are then the values at the
knots themselves (exact zeros stay exact).

Derivatives use the same identity: ``D^j N = n!/(n-j)! w^{-j} Σ_k (Δ^j β)_{r,k} B_{k,n-j}(s)``,
tabulated per order. An evaluation is then a span look-up, the Bernstein values of
``s`` and one small contraction per parameter: a few vector operations for any number
of parameters, and plain floats for one.
"""

from __future__ import annotations

from dataclasses import dataclass
from math import comb, factorial

import numpy as np
from numpy.typing import NDArray

from .deboor import BLOCK, triangle

Array = NDArray[np.float64]


@dataclass(frozen=True)
class SpanForm:
    """Bernstein coefficients of the non-zero B-splines, per span and derivative order.

    ``coefficients[j][i, r, k]`` is the coefficient of ``B_{k,n-j}(s)`` in ``D^j N_{first[i]+r}``
    on span ``i`` (the factors ``n!/(n-j)! w_i^{-j}`` included), ``j = 0..n``.
    """

    degree: int
    coefficients: tuple[Array, ...]

    def values(self, span: NDArray[np.int64], s: Array, max_derivative: int) -> Array:
        """``D^j N_{first+r}`` at local parameters ``s`` on spans ``span`` (both shape ``(N,)``).

        Returns shape ``(max_derivative + 1, N, n + 1)``; orders above ``n`` are zero.
        Works through blocks of :data:`splinedeform.deboor.BLOCK` parameters.
        """
        n = self.degree
        top = min(max_derivative, n)
        if s.size <= BLOCK and max_derivative == 0:             # the common case, one product
            return np.einsum("prk,kp->pr", self.coefficients[0][span], bernstein(s, n))[None]
        out = np.zeros((max_derivative + 1, s.size, n + 1))
        for start in range(0, s.size, BLOCK):
            block = slice(start, start + BLOCK)
            for j in range(top + 1):
                # Σ_k β^{(j)}_{r,k} B_{k,n-j}(s): gathered coefficients against Bernstein values
                np.einsum("prk,kp->pr", self.coefficients[j][span[block]],
                          bernstein(s[block], n - j), out=out[j, block])
        return out


def scalar_bernstein(s: float, degree: int) -> list[float]:
    """:func:`bernstein` of one parameter, as a list of ``m + 1`` floats."""
    t = 1.0 - s
    out = _binomials(degree).copy()               # C(m,k) s^k (1-s)^{m-k}: the powers of t
    power = 1.0                                   # from the right, those of s from the left
    for k in range(degree, -1, -1):
        out[k] *= power
        power *= t
    power = s
    for k in range(1, degree + 1):
        out[k] *= power
        power *= s
    return out


def _binomials(m: int) -> list[float]:
    return _BINOMIALS[m] if m < len(_BINOMIALS) else [float(comb(m, k)) for k in range(m + 1)]


_BINOMIALS = [[float(comb(m, k)) for k in range(m + 1)] for m in range(16)]


def bernstein(s: Array, degree: int) -> Array:
    """Bernstein polynomials ``B_{k,m}(s) = C(m,k) s^k (1-s)^{m-k}``, shape ``(m+1, N)``.

    Products of the powers of ``s`` and ``1 - s``: no cancellation, and exact where
    ``s`` is 0 or 1 (at knots).
    """
    m = degree
    t = 1.0 - s
    powers_s, powers_t = [s], [t]
    for _ in range(m - 1):
        powers_s.append(powers_s[-1] * s)
        powers_t.append(powers_t[-1] * t)
    out = np.empty((m + 1, s.size))
    if m == 0:
        out[0] = 1.0
        return out
    out[0] = powers_t[m - 1]
    out[m] = powers_s[m - 1]
    for k in range(1, m):
        np.multiply(powers_s[k - 1], powers_t[m - k - 1], out=out[k])
        out[k] *= comb(m, k)
    return out


def span_form(left: Array, right: Array, widths: Array, degree: int) -> SpanForm:
    """:class:`SpanForm` of spans given by their knot windows at the left end.

    Parameters
    ----------
    left, right : ndarray, shape ``(n, S)``
        ``t_μ - t_{μ+1-k}`` and ``t_{μ+k} - t_μ`` (``k = 1..n``) of each span, in any
        unit (``right[0]`` is the span width in that unit).
    widths : ndarray, shape ``(S,)``
        Span widths ``w = t_{μ+1} - t_μ > 0`` in the unit derivatives are taken in.
    degree : int
    """
    n = degree
    width = right[0]                                          # w in the unit of left/right
    powers = width ** np.arange(n + 1)[:, None, None]         # d^j/ds^j = w^j D^j
    at_left = triangle(left, right, n, n) * powers            # p^{(j)}(0): (j, r, S)
    at_right = triangle(left + width, right - width, n, n) * powers   # p^{(j)}(1)
    beta = np.zeros((widths.size, n + 1, n + 1))
    for k in range(n + 1):
        # the nearer end gives each coefficient exactly where it is a value (k = 0, n)
        # and with the fewest terms otherwise
        near, sign, order = (at_left, 1.0, k) if k <= n // 2 else (at_right, -1.0, n - k)
        for j in range(order + 1):
            beta[:, :, k] += (comb(order, j) * factorial(n - j) / factorial(n)
                              * sign ** j) * near[j].T
    coefficients = tuple(
        np.ascontiguousarray(np.diff(beta, n=j, axis=2)
                             * (factorial(n) / factorial(n - j) * widths ** (-j))[:, None, None])
        for j in range(n + 1))
    return SpanForm(n, coefficients)
