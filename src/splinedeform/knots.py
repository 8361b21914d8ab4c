"""B-spline bases over a general (non-uniform, clamped) knot vector.

A knot vector ``t_0 <= t_1 <= … <= t_{N+n}`` of degree ``n`` defines ``N`` B-splines
``N_{k,n}`` by the Cox–de Boor recurrence

.. math:: N_{k,p}(x) = \\frac{x - t_k}{t_{k+p} - t_k} N_{k,p-1}(x)
          + \\frac{t_{k+p+1} - x}{t_{k+p+1} - t_{k+1}} N_{k+1,p-1}(x)

on the parameter domain ``[t_n, t_N]``. Interior knots may be repeated up to ``n``
times (a knot of multiplicity ``μ`` leaves the spline ``C^{n-μ}`` there). This is the
layout CAD programs write; the uniform / open / periodic layouts of
:class:`splinedeform.basis.BSplineBasis` are its fast special cases.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from bisect import bisect_right
from math import comb

import numpy as np
import scipy.sparse as sp
from numpy.typing import ArrayLike, NDArray

from .basis import _check_degree
from .spans import SpanForm, span_form
from .errors import InputError


@dataclass(frozen=True)
class KnotVectorBasis:
    """B-spline basis of degree ``n`` from a knot vector (splipy / openNURBS style).

    Parameters
    ----------
    degree : int
        Polynomial degree ``n >= 1``.
    knots : array_like
        Non-decreasing knots ``t_0 … t_{N+n}`` (``N + n + 1`` values, ``N >= n + 1``),
        interior multiplicity at most ``n``; the domain is ``[t_n, t_N]``.

    Examples
    --------
    >>> b = KnotVectorBasis(2, [0, 0, 0, 0.5, 0.5, 1, 1, 1])
    >>> b.size, b.domain
    (5, (0.0, 1.0))
    >>> round(float(b([0.3]).sum()), 12)
    1.0
    """

    degree: int
    knots: NDArray[np.float64]
    breaks: NDArray[np.float64] = field(init=False, repr=False, compare=False)
    widths: NDArray[np.float64] = field(init=False, repr=False, compare=False)
    first: NDArray[np.int64] = field(init=False, repr=False, compare=False)
    form: SpanForm = field(init=False, repr=False, compare=False)
    _break_list: list = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        _check_degree(self.degree)
        t = np.asarray(self.knots, dtype=float).ravel()
        n = self.degree
        if t.size < 2 * n + 2:
            raise InputError(f"a degree-{n} knot vector needs at least {2 * n + 2} knots, "
                             f"got {t.size}")
        if not np.all(np.isfinite(t)) or np.any(np.diff(t) < 0):
            raise InputError("knots must be finite and non-decreasing")
        lo, hi = t[n], t[t.size - n - 1]
        if not hi > lo:
            raise InputError(f"knot vector has an empty domain [t_n, t_N] = [{lo:g}, {hi:g}]")
        inner = t[(t > lo) & (t < hi)]
        if inner.size:
            _, mult = np.unique(inner, return_counts=True)
            if mult.max() > n:
                raise InputError(f"an interior knot is repeated {mult.max()} times; "
                                 f"at most the degree ({n}) keeps the basis continuous")
        t.setflags(write=False)
        object.__setattr__(self, "knots", t)
        breaks = np.unique(t[n:t.size - n])
        object.__setattr__(self, "breaks", breaks)
        # the non-empty spans: knot index μ with t_μ = breaks[i] < t_{μ+1}
        mu = np.searchsorted(t, breaks[:-1], side="right") - 1
        k = np.arange(1, n + 1)[:, None]
        object.__setattr__(self, "widths", np.diff(breaks))
        object.__setattr__(self, "_break_list", breaks.tolist())
        object.__setattr__(self, "first", mu - n)
        object.__setattr__(self, "form", span_form(t[mu] - t[mu + 1 - k], t[mu + k] - t[mu],
                                                   self.widths, n))

    @property
    def size(self) -> int:
        """Number of basis functions ``N = len(knots) - n - 1``."""
        return self.knots.size - self.degree - 1

    @property
    def domain(self) -> tuple[float, float]:
        """Parameter domain ``[t_n, t_N]``."""
        return float(self.breaks[0]), float(self.breaks[-1])

    @property
    def periodic(self) -> bool:
        return False

    #: layout name, as :attr:`splinedeform.basis.BSplineBasis.kind`
    kind = "general"

    @property
    def length(self) -> float:
        """Right end ``t_N`` of the domain; a :class:`~splinedeform.surface.Surface` needs
        ``t_n = 0`` (its parameters run over ``[0, L]``), so this is ``L`` there."""
        return float(self.breaks[-1])

    @property
    def cells(self) -> int:
        """Number of non-empty knot spans."""
        return self.breaks.size - 1

    @property
    def continuity(self) -> int:
        """Order ``k`` with every spline ``C^k`` on the domain: ``n - μ_max`` for the largest
        interior knot multiplicity ``μ_max`` (``n`` without interior knots)."""
        t, n = self.knots, self.degree
        inner = t[(t > self.breaks[0]) & (t < self.breaks[-1])]
        return n - (int(np.unique(inner, return_counts=True)[1].max()) if inner.size else 0)

    @property
    def c0_knots(self) -> NDArray[np.float64]:
        """Interior knots repeated ``n`` times (where the splines are only ``C^0``)."""
        t, n = self.knots, self.degree
        values, counts = np.unique(t[(t > self.breaks[0]) & (t < self.breaks[-1])],
                                   return_counts=True)
        return values[counts >= n]

    def shifted(self, origin: float) -> KnotVectorBasis:
        """The same basis over the knots ``t_i - origin`` (domain moved by ``-origin``)."""
        return KnotVectorBasis(self.degree, self.knots - origin)

    def greville(self) -> NDArray[np.float64]:
        """Greville abscissae ``ξ_k = (t_{k+1} + … + t_{k+n}) / n``."""
        n = self.degree
        window = np.lib.stride_tricks.sliding_window_view(self.knots[1:-1], n)[: self.size]
        return window.mean(axis=1)

    def span(self, x: ArrayLike) -> NDArray[np.int64]:
        """Knot index ``μ`` with ``t_μ <= x < t_{μ+1}``, ``n <= μ <= N-1`` (last span closed)."""
        x = self._check_points(x)
        n, t = self.degree, self.knots
        mu = np.searchsorted(t, x, side="right") - 1
        return np.clip(mu, n, self.size - 1)

    def _check_points(self, x: ArrayLike) -> NDArray[np.float64]:
        x = np.asarray(x, dtype=float)
        lo, hi = self.domain
        if not np.all(np.isfinite(x)):
            raise InputError("parameters must be finite numbers")
        tol = 1e-12 * (hi - lo)
        if x.size and (x.min() < lo - tol or x.max() > hi + tol):
            raise InputError(f"parameter outside the domain [{lo:g}, {hi:g}]: "
                             f"got values in [{x.min():g}, {x.max():g}]")
        return np.clip(x, lo, hi)

    def nonzero_derivatives(self, x: ArrayLike, max_derivative: int = 0
                            ) -> tuple[NDArray[np.int64], NDArray[np.float64]]:
        """Indices ``μ-n … μ`` and ``D^j N_k(x)`` for ``j = 0..max_derivative``.

        Same shapes as :meth:`splinedeform.basis.BSplineBasis.nonzero_derivatives`.
        """
        if not isinstance(max_derivative, (int, np.integer)) or max_derivative < 0:
            raise InputError(f"derivative order must be an integer >= 0, got {max_derivative!r}")
        x = np.asarray(x, dtype=float)
        span, s = self.locate(x)
        values = self.form.values(span, s, max_derivative)
        index = self.first[span].reshape(x.shape)[..., None] + np.arange(self.degree + 1)
        return index, values.reshape((max_derivative + 1,) + x.shape + (self.degree + 1,))

    def locate(self, x: ArrayLike) -> tuple[NDArray[np.int64], NDArray[np.float64]]:
        """Non-empty span ``i`` (``breaks[i] <= x``) and local ``s = (x - breaks[i]) / w_i`` (flattened)."""
        flat = self._check_points(x).ravel()
        b = self.breaks
        span = np.clip(np.searchsorted(b, flat, side="right") - 1, 0, b.size - 2)
        return span, (flat - b[span]) / self.widths[span]

    def locate_scalar(self, x: float) -> tuple[int, float]:
        """:meth:`locate` of one parameter, in plain Python numbers."""
        b = self._break_list
        if not b[0] <= x <= b[-1]:                 # also refuses NaN and infinities
            self._check_points(x)                  # says why (or accepts a rounding error)
            x = min(max(x, b[0]), b[-1])
        span = bisect_right(b, x) - 1
        if span >= len(b) - 1:
            span = len(b) - 2
        return span, (x - b[span]) / (b[span + 1] - b[span])

    def span_functions(self) -> NDArray[np.int64]:
        """Indices of the ``n + 1`` functions not vanishing on each non-empty span."""
        return self.first[:, None] + np.arange(self.degree + 1)

    def nonzero(self, x: ArrayLike, derivative: int = 0
                ) -> tuple[NDArray[np.int64], NDArray[np.float64]]:
        """Indices and values of the ``n+1`` functions not vanishing at each parameter."""
        index, values = self.nonzero_derivatives(x, derivative)
        return index, values[derivative]

    def matrix(self, x: ArrayLike, derivative: int = 0) -> sp.csr_matrix:
        """Sparse collocation matrix ``A_{ij} = D^derivative N_j(x_i)``."""
        x = np.atleast_1d(np.asarray(x, dtype=float)).ravel()
        index, values = self.nonzero(x, derivative)
        indptr = np.arange(0, x.size * (self.degree + 1) + 1, self.degree + 1)
        return sp.csr_matrix((values.ravel(), index.ravel(), indptr), shape=(x.size, self.size))

    def __call__(self, x: ArrayLike, derivative: int = 0) -> NDArray[np.float64]:
        """Dense collocation matrix."""
        return self.matrix(x, derivative).toarray()


@dataclass(frozen=True)
class RationalBasis:
    """Weighted (NURBS) basis ``R_k = w_k N_k / W`` with ``W = Σ_j w_j N_j``.

    Derivatives follow from Leibniz' rule applied to ``W R_k = w_k N_k``:

    .. math:: D^j R_k = \\Big(w_k D^j N_k - \\sum_{i=1}^{j} \\binom{j}{i} D^i W\\, D^{j-i} R_k\\Big) / W.

    ``R_k`` is not a polynomial on a knot span, so Gram matrices of this basis are
    computed by quadrature with :attr:`points_per_cell` Gauss points per span (exact
    when all weights are equal, where ``R_k = N_k``).

    Parameters
    ----------
    basis : KnotVectorBasis
    weights : array_like, shape ``(basis.size,)``
        Positive weights ``w_k``.

    Examples
    --------
    >>> r = RationalBasis(KnotVectorBasis(2, [0, 0, 0, 1, 1, 1]), [1, 0.5 ** 0.5, 1])
    >>> x, y = r([0.3]) @ [[1, 0], [1, 1], [0, 1]] @ [1, 0], r([0.3]) @ [0, 1, 1]
    >>> round(float(x[0] ** 2 + y[0] ** 2), 12)   # a quarter of the unit circle
    1.0
    """

    basis: KnotVectorBasis
    weights: NDArray[np.float64]
    points_per_cell: int = 0

    def __post_init__(self) -> None:
        w = np.asarray(self.weights, dtype=float).ravel()
        if w.shape != (self.basis.size,):
            raise InputError(f"a rational basis needs {self.basis.size} weights (one per "
                             f"function), got {w.size}")
        if not np.all(np.isfinite(w)) or np.any(w <= 0):
            raise InputError("NURBS weights must be finite and > 0")
        w.setflags(write=False)
        object.__setattr__(self, "weights", w)
        if not self.points_per_cell:
            object.__setattr__(self, "points_per_cell", 2 * self.basis.degree + 10)

    degree = property(lambda self: self.basis.degree)
    size = property(lambda self: self.basis.size)
    breaks = property(lambda self: self.basis.breaks)
    domain = property(lambda self: self.basis.domain)
    periodic = property(lambda self: False)
    length = property(lambda self: self.basis.length)
    cells = property(lambda self: self.basis.cells)
    knots = property(lambda self: self.basis.knots)
    continuity = property(lambda self: self.basis.continuity)
    c0_knots = property(lambda self: self.basis.c0_knots)
    kind = "rational"

    def greville(self) -> NDArray[np.float64]:
        """Greville abscissae of the polynomial basis (the weights do not move them)."""
        return self.basis.greville()

    def span(self, x: ArrayLike) -> NDArray[np.int64]:
        return self.basis.span(x)

    def nonzero_derivatives(self, x: ArrayLike, max_derivative: int = 0
                            ) -> tuple[NDArray[np.int64], NDArray[np.float64]]:
        """Indices and ``D^j R_k(x)``, ``j = 0..max_derivative`` (shapes as the polynomial basis)."""
        index, b = self.basis.nonzero_derivatives(x, max_derivative)
        return index, self.rational(index, b)

    def rational(self, index: NDArray[np.int64], b: NDArray[np.float64]) -> NDArray[np.float64]:
        """``D^j R_k`` from the polynomial ``D^j N_k`` (``b[j]``) of the functions ``index``."""
        wb = b * self.weights[index]                 # w_k D^j N_k
        W = wb.sum(axis=-1, keepdims=True)           # D^j W
        R = np.empty_like(wb)
        for j in range(b.shape[0]):
            acc = wb[j].copy()
            for i in range(1, j + 1):
                acc -= comb(j, i) * W[i] * R[j - i]
            R[j] = acc / W[0]
        return R

    nonzero = KnotVectorBasis.nonzero
    matrix = KnotVectorBasis.matrix
    __call__ = KnotVectorBasis.__call__


def one_sided(basis: object, x: float, side: int, max_derivative: int = 1
              ) -> tuple[NDArray[np.int64], NDArray[np.float64]]:
    """The ``n + 1`` functions of the span on one side of ``x`` and their one-sided derivatives.

    ``side = -1`` takes the span ending at ``x`` (the limits from below), ``side = +1`` the
    span starting there (from above); inside a span both are the ordinary values. At a
    ``C^0`` knot the first derivatives of the two sides differ, which is what a coupling
    across it compares. The span's Bézier form (:mod:`splinedeform.spans`) is evaluated at
    its local end parameter ``s = 1`` or ``s = 0`` exactly.

    Parameters
    ----------
    basis : BSplineBasis, KnotVectorBasis or RationalBasis
    x : float
        A parameter in the domain.
    side : {-1, +1}
    max_derivative : int

    Returns
    -------
    index : ndarray of int, shape ``(n + 1,)``
    values : ndarray, shape ``(max_derivative + 1, n + 1)``
        ``D^j`` of those functions at ``x`` from the chosen side.

    Examples
    --------
    >>> b = KnotVectorBasis(2, [0, 0, 0, 0.5, 0.5, 1, 1, 1])
    >>> below, above = one_sided(b, 0.5, -1)[1][1], one_sided(b, 0.5, +1)[1][1]
    >>> [float(v) for v in below], [float(v) for v in above]
    ([0.0, -4.0, 4.0], [-4.0, 4.0, 0.0])
    """
    if side not in (-1, 1):
        raise InputError(f"side is -1 (from below) or +1 (from above), got {side!r}")
    polynomial = basis.basis if isinstance(basis, RationalBasis) else basis
    breaks = getattr(polynomial, "breaks", None)
    if breaks is None:                               # equal cells of a BSplineBasis
        breaks = np.arange(polynomial.cells + 1) * polynomial.h
    x = float(polynomial._check_points(x))
    span = int(np.searchsorted(breaks, x, side="left" if side < 0 else "right")) - 1
    span = min(max(span, 0), breaks.size - 2)
    s = (x - breaks[span]) / (breaks[span + 1] - breaks[span])
    values = polynomial.form.values(np.array([span]), np.array([s]), max_derivative)[:, 0]
    index = polynomial.span_functions()[span]
    if isinstance(basis, RationalBasis):
        values = basis.rational(index, values)
    return index, values
