"""One-dimensional B-spline bases on a parameter interval ``[0, L]``.

Three knot layouts are supported, all with ``m`` equal cells of width ``h = L/m``:

``"uniform"``
    Höllig's scaled and translated uniform B-splines ``b^n_{k,h}(x) = b^n(x/h - k)``
    for ``k = -n, ..., m-1`` (``m + n`` functions), evaluated by the recurrence

    .. math:: b^n(x) = \\frac{x}{n} b^{n-1}(x) + \\frac{n+1-x}{n} b^{n-1}(x-1).

``"open"``
    Clamped knot vector (end knots repeated ``n+1`` times, uniform interior),
    ``m + n`` functions; the spline interpolates its end coefficients.

``"periodic"``
    Uniform B-splines wrapped around the interval, ``m`` functions; the spline
    and its first ``n-1`` derivatives are continuous across ``x = L ≡ 0``.

Function index ``j`` (0-based) of a uniform basis is Höllig's ``k = j - n``.
On cell ``i`` the non-zero functions are ``j = i, ..., i + n`` (modulo ``m`` when
periodic), so every evaluation returns ``n + 1`` values per parameter.

Evaluation: each basis keeps the Bernstein coefficients of its non-zero functions on
every cell (:mod:`splinedeform.spans`, found once from the Cox–de Boor recurrence of the
knot vector); a parameter's values are then its cell's coefficients against the Bernstein
polynomials of its local parameter ``s = x/h - i``, for all parameters at once.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from math import comb, isfinite
from typing import Literal

import numpy as np
import scipy.sparse as sp
from numpy.typing import ArrayLike, NDArray

from .errors import InputError
from .spans import SpanForm, span_form

KnotKind = Literal["uniform", "open", "periodic"]
KNOT_KINDS: tuple[str, ...] = ("uniform", "open", "periodic")


def cardinal_bspline(x: ArrayLike, degree: int) -> NDArray[np.float64]:
    """Höllig's uniform B-spline ``b^n(x)`` of degree ``n`` at any ``x``.

    Uses the recurrence ``b^n(x) = x/n b^{n-1}(x) + (n+1-x)/n b^{n-1}(x-1)``
    starting from ``b^0 = 1`` on ``[0, 1)``. Support ``[0, n+1]``.
    """
    _check_degree(degree)
    x = np.asarray(x, dtype=float)
    cell = np.floor(x)
    s = x - cell
    table = _hollig_table(s, degree, 0)[0]  # (N..., n+1): b^n(s + q), q = 0..n
    q = cell.astype(int)
    inside = (q >= 0) & (q <= degree)
    out = np.take_along_axis(table, np.clip(q, 0, degree)[..., None], axis=-1)[..., 0]
    return np.where(inside, out, 0.0)


def _hollig_table(s: NDArray[np.float64], degree: int, max_derivative: int
                  ) -> list[NDArray[np.float64]]:
    """Values ``D^j b^n(s + q)`` for ``q = 0..n`` and ``j = 0..max_derivative``.

    ``s`` in ``[0, 1]``. Derivatives from ``D^j b^n(y) = Σ_i (-1)^i C(j,i) b^{n-j}(y-i)``
    (DESIGN.md §1.1, unscaled: ``h = 1``). Returns a list indexed by ``j`` of
    arrays of shape ``s.shape + (n+1,)``.
    """
    # levels[d][q] = b^d(s + q), q = 0..d, kept as a leading axis so each update is contiguous
    flat = np.ravel(s)
    levels = [np.ones((1, flat.size))]
    for d in range(1, degree + 1):
        prev = levels[-1]
        new = np.zeros((d + 1, flat.size))
        y = flat + np.arange(d + 1)[:, None]
        new[:d] = y[:d] * prev                   # (s+q)/d · b^{d-1}(s+q)
        new[1:] += (d + 1 - y[1:]) * prev        # (d+1-s-q)/d · b^{d-1}(s+q-1)
        levels.append(new / d)
    out = []
    for j in range(max_derivative + 1):
        low = levels[degree - j]  # b^{n-j}(s + q), q = 0..n-j
        acc = np.zeros((degree + 1, flat.size))
        for i in range(j + 1):
            # b^{n-j}(s + q - i) sits at q = i .. i + n - j
            acc[i:i + degree - j + 1] += (-1) ** i * comb(j, i) * low
        out.append(np.moveaxis(acc, 0, -1).reshape(np.shape(s) + (degree + 1,)))
    return out


def _check_degree(degree: int) -> None:
    if not isinstance(degree, (int, np.integer)) or isinstance(degree, bool) or degree < 1:
        raise InputError(f"degree must be an integer >= 1, got {degree!r}")


@dataclass(frozen=True)
class BSplineBasis:
    """A B-spline basis of degree ``n`` on ``[0, length]`` with ``cells`` equal cells.

    Parameters
    ----------
    degree : int
        Polynomial degree ``n >= 1``.
    cells : int
        Number of equal knot spans ``m`` on the interval; at least 1 (``n+1`` if periodic).
    length : float
        Length ``L`` of the parameter interval.
    kind : {"uniform", "open", "periodic"}
        Knot layout, see the module docstring.

    Examples
    --------
    >>> b = BSplineBasis(3, 4, 1.0, "open")
    >>> b.size
    7
    >>> round(float(b.matrix([0.3]).sum()), 12)
    1.0
    """

    degree: int
    cells: int
    length: float = 1.0
    kind: KnotKind = "open"
    knots: NDArray[np.float64] = field(init=False, repr=False, compare=False)
    form: SpanForm = field(init=False, repr=False, compare=False)
    _span_functions: NDArray[np.int64] = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        _check_degree(self.degree)
        if self.kind not in KNOT_KINDS:
            raise InputError(f"knot kind must be one of {KNOT_KINDS}, got {self.kind!r}")
        if not isinstance(self.cells, (int, np.integer)) or isinstance(self.cells, bool):
            raise InputError(f"cells must be an integer, got {self.cells!r}")
        minimum = self.degree + 1 if self.kind == "periodic" else 1
        if self.cells < minimum:
            raise InputError(
                f"a {self.kind} basis of degree {self.degree} needs at least {minimum} cell(s), "
                f"got {self.cells}" + (" (a periodic direction needs cells >= degree + 1)"
                                       if self.kind == "periodic" else ""))
        if not np.isfinite(self.length) or self.length <= 0:
            raise InputError(f"parameter length must be finite and > 0, got {self.length!r}")
        object.__setattr__(self, "length", float(self.length))
        object.__setattr__(self, "knots", self._knot_vector())
        below, above = self._cell_windows()
        object.__setattr__(self, "form", span_form(-below, above, np.full(self.cells, self.h),
                                                   self.degree))
        index = np.arange(self.cells)[:, None] + np.arange(self.degree + 1)
        object.__setattr__(self, "_span_functions", np.mod(index - self.degree, self.cells)
                           if self.kind == "periodic" else index)

    # -- layout -------------------------------------------------------------
    @property
    def h(self) -> float:
        """Cell width ``h = L / m``."""
        return self.length / self.cells

    @property
    def size(self) -> int:
        """Number of basis functions (control points in this direction)."""
        return self.cells if self.kind == "periodic" else self.cells + self.degree

    @property
    def periodic(self) -> bool:
        return self.kind == "periodic"

    def _knot_vector(self) -> NDArray[np.float64]:
        n, m, h = self.degree, self.cells, self.h
        if self.kind == "open":
            return np.concatenate([np.zeros(n), np.arange(m + 1) * h, np.full(n, self.length)])
        # uniform and periodic: the bi-infinite grid hZ, restricted to the functions used
        return np.arange(-n, m + n + 1) * h

    def _cell_windows(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Knots ``τ_{μ+1-k} - i`` and ``τ_{μ+k} - i`` (``k = 1..n``) of each cell ``i``, in cells.

        ``τ = t / h`` are the knots in units of the cell width (integers), ``μ = i + n`` the
        knot index starting cell ``i``; shape ``(n, m)`` each. With the local parameter
        ``s = x/h - i`` the recurrence's ``left_k = s - (τ_{μ+1-k} - i)`` and
        ``right_k = (τ_{μ+k} - i) - s`` are exact at the cell's left end ``s = 0``, where
        :func:`splinedeform.spans.span_form` takes them.
        """
        n, m = self.degree, self.cells
        if self.kind == "open":
            tau = np.concatenate([np.zeros(n), np.arange(m + 1.0), np.full(n, float(m))])
        else:
            tau = np.arange(-n, m + n + 1.0)
        cell = np.arange(m)
        k = np.arange(1, n + 1)[:, None]
        return tau[cell + n + 1 - k] - cell, tau[cell + n + k] - cell

    def greville(self) -> NDArray[np.float64]:
        """Greville abscissae ``ξ_j = (t_{j+1} + … + t_{j+n}) / n`` inside ``[0, L]``.

        For uniform (Höllig) knots the knot averages of the outer functions fall
        outside the interval; the abscissae of the open layout on the same cells are
        used instead. On ``[0, L]`` both layouts span the same splines, so these points
        satisfy the Schoenberg–Whitney condition, and the collocation matrix stays well
        conditioned as ``m`` grows (equally spaced points do not: its condition number
        grows exponentially with ``m`` for ``n >= 3``). For periodic knots they are the
        support centres ``(j + (n+1)/2) h`` modulo ``L``.
        """
        n, h = self.degree, self.h
        if self.kind == "periodic":
            return np.mod((np.arange(self.size) + (n + 1) / 2) * h, self.length)
        if self.kind == "uniform":
            return BSplineBasis(n, self.cells, self.length, "open").greville()
        t = self.knots
        window = np.lib.stride_tricks.sliding_window_view(t[1:-1], n)[: self.size]
        return window.mean(axis=1)

    # -- evaluation ---------------------------------------------------------
    def _check_points(self, x: ArrayLike) -> NDArray[np.float64]:
        x = np.asarray(x, dtype=float)
        if not x.size:
            return x
        lo, hi = x.min(), x.max()                  # NaN and infinities show in these
        if not (np.isfinite(lo) and np.isfinite(hi)):
            raise InputError("parameters must be finite numbers")
        if self.kind == "periodic":
            return np.mod(x, self.length)
        tol = 1e-12 * self.length
        if lo < -tol or hi > self.length + tol:
            raise InputError(
                f"parameter outside the domain [0, {self.length:g}]: "
                f"got values in [{lo:g}, {hi:g}]")
        return np.clip(x, 0.0, self.length) if lo < 0.0 or hi > self.length else x

    def span(self, x: ArrayLike) -> NDArray[np.int64]:
        """Index ``i`` of the cell ``[i h, (i+1) h)`` holding each parameter (last cell closed)."""
        x = self._check_points(x)
        return np.clip(np.floor(x / self.h).astype(np.int64), 0, self.cells - 1)

    def nonzero(self, x: ArrayLike, derivative: int = 0
                ) -> tuple[NDArray[np.int64], NDArray[np.float64]]:
        """Indices and values of the ``n+1`` functions not vanishing at each parameter.

        Parameters
        ----------
        x : array_like
            Parameters in ``[0, L]`` (any shape ``S``; any real number when periodic).
        derivative : int
            Order ``j`` of the derivative, ``0 <= j``; orders above ``n`` give zeros.

        Returns
        -------
        index : ndarray of int, shape ``S + (n+1,)``
        value : ndarray of float, shape ``S + (n+1,)``
            ``D^j b_index(x)``.
        """
        index, values = self.nonzero_derivatives(x, derivative)
        return index, values[derivative]

    def nonzero_derivatives(self, x: ArrayLike, max_derivative: int = 0
                            ) -> tuple[NDArray[np.int64], NDArray[np.float64]]:
        """Like :meth:`nonzero` but for all orders ``0..max_derivative`` at once.

        Returns ``index`` of shape ``S + (n+1,)`` and ``values`` of shape
        ``(max_derivative+1,) + S + (n+1,)``.
        """
        if not isinstance(max_derivative, (int, np.integer)) or max_derivative < 0:
            raise InputError(f"derivative order must be an integer >= 0, got {max_derivative!r}")
        x = np.asarray(x, dtype=float)
        cell, s = self.locate(x)
        values = self.form.values(cell, s, max_derivative)
        index = self._span_functions[cell].reshape(x.shape + (self.degree + 1,))
        return index, values.reshape((max_derivative + 1,) + x.shape + (self.degree + 1,))

    def locate(self, x: ArrayLike) -> tuple[NDArray[np.int64], NDArray[np.float64]]:
        """Cell ``i`` and local parameter ``s = x/h - i ∈ [0, 1]`` of each parameter (flattened)."""
        y = self._check_points(x).ravel() / self.h
        cell = y.astype(np.int64)                  # y >= 0: truncation is the floor
        np.minimum(cell, self.cells - 1, out=cell)   # x = L belongs to the last cell
        return cell, y - cell

    def locate_scalar(self, x: float) -> tuple[int, float]:
        """:meth:`locate` of one parameter, in plain Python numbers."""
        L = self.length
        if self.kind == "periodic" and isfinite(x):
            x = x % L
        if not 0.0 <= x <= L:                      # also refuses NaN and infinities
            self._check_points(x)                  # says why (or accepts a rounding error)
            x = min(max(x, 0.0), L)
        y = x / self.h
        cell = int(y)
        if cell >= self.cells:
            cell = self.cells - 1
        return cell, y - cell

    def span_functions(self) -> NDArray[np.int64]:
        """Indices of the ``n + 1`` functions not vanishing on each cell, shape ``(m, n+1)``."""
        return self._span_functions.copy()

    def matrix(self, x: ArrayLike, derivative: int = 0) -> sp.csr_matrix:
        """Sparse collocation matrix ``A_{ij} = D^derivative b_j(x_i)``, shape ``(len(x), size)``."""
        x = np.atleast_1d(np.asarray(x, dtype=float)).ravel()
        index, values = self.nonzero(x, derivative)
        # exactly n+1 entries per row: build the CSR arrays directly (no COO round trip)
        indptr = np.arange(0, x.size * (self.degree + 1) + 1, self.degree + 1)
        return sp.csr_matrix((values.ravel(), index.ravel(), indptr), shape=(x.size, self.size))

    def __call__(self, x: ArrayLike, derivative: int = 0) -> NDArray[np.float64]:
        """Dense collocation matrix; convenient for small problems and tests."""
        return self.matrix(x, derivative).toarray()
