"""Refinement of a surface that leaves its geometry unchanged: knot insertion and degree
elevation, polynomial and rational.

Both operations replace a 1-D basis ``N_old`` by a larger one ``N_new`` whose span contains
it on the parameter domain, ``N_old(x) = N_new(x) T`` with a refinement matrix ``T``
(``n_new × n_old``); the control points then map as ``P_new = T P_old`` and the curve
``N_old P_old = N_new P_new`` does not move. A rational direction (weights ``a``,
``R = a N / (N a)``) is refined in homogeneous coordinates ``(a P, a)``:

.. math:: a' = T a, \\qquad P' = T (a P) / a',

so the weight function ``W = N_old a = N_new a'`` and the surface are unchanged, and the
new weights, convex combinations of the old ones, stay positive. A surface is refined one
direction at a time, so weights that are a product ``a_i b_j`` stay a product.

- **Knot insertion** (Boehm's algorithm): inserting ``x`` with ``t_μ <= x < t_{μ+1}`` into
  a degree-``n`` knot vector gives the points ``c'_i = c_i`` for ``i <= μ - n``,
  ``c'_i = α_i c_i + (1 - α_i) c_{i-1}`` with ``α_i = (x - t_i) / (t_{i+n} - t_i)`` for
  ``μ - n < i <= μ``, and ``c'_i = c_{i-1}`` for ``i > μ``. Applied to general knot
  vectors (CAD surfaces). The equal-cell layouts of :class:`~splinedeform.basis.BSplineBasis`
  stay in their layout with ``(k + 1) m`` cells (Höllig's uniform and periodic layouts have
  knots outside the domain that Boehm's algorithm would leave unequal); their ``T`` solves
  ``N_new T = N_old`` in the least-squares sense at ``n + 1`` Gauss points per new cell,
  which is exact since the old space lies in the new one.
- **Degree elevation** by ``p``: the splines of degree ``n + p`` on the same breaks with the
  same continuity ``C^{n-μ}`` at a knot of multiplicity ``μ`` contain the old ones (each
  distinct knot's multiplicity rises by ``p``; the ends are clamped, multiplicity
  ``n + p + 1``). ``T`` solves ``N_new(ξ) T = N_old(ξ)`` at the new basis' Greville points
  ``ξ`` (Schoenberg–Whitney holds there, so the collocation is exact up to round-off).
  Not defined in the periodic layout (the elevated periodic space has knots of
  multiplicity ``p + 1``); refused there.

Elevation is done before insertion (k-refinement): the inserted knots are then simple
knots of the elevated degree, with its full continuity.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from .basis import BSplineBasis
from .errors import InputError
from .knots import KnotVectorBasis, RationalBasis
from .quadrature import gauss_points
from .surface import Basis, Surface

#: largest number of knots inserted per span, and of degrees added (the bases stay small)
MAX_INSERT, MAX_ELEVATE = 64, 6
#: most functions a refined direction may have (its refinement matrix is dense)
MAX_SIZE = 1024


def boehm_insert(knots: NDArray[np.float64], degree: int, x: float, points: NDArray[np.float64]
                 ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Insert one knot ``x`` (Boehm's algorithm, see the module docstring).

    ``points`` has the ``N`` coefficients along its first axis (control points, or the
    columns of a refinement matrix); returns the new knot vector and the ``N + 1`` new
    coefficients.
    """
    t, n, c = np.asarray(knots, dtype=float), degree, np.asarray(points, dtype=float)
    size = t.size - n - 1
    mu = int(np.searchsorted(t, x, side="right")) - 1
    if not (t[n] <= x < t[size]) or mu < n or c.shape[0] != size:
        raise InputError(f"knot {x:g} lies outside the domain [{t[n]:g}, {t[size]:g}), or "
                         f"{c.shape[0]} coefficients for {size} functions")
    i = np.arange(mu - n + 1, mu + 1)
    alpha = ((x - t[i]) / (t[i + n] - t[i])).reshape((-1,) + (1,) * (c.ndim - 1))
    middle = alpha * c[i] + (1.0 - alpha) * c[i - 1]
    return np.insert(t, mu + 1, x), np.concatenate([c[:mu - n + 1], middle, c[mu:]])


def insert_knots(basis: Basis, k: int) -> tuple[Basis, NDArray[np.float64]]:
    """``k`` knots inserted at equal distances into every non-empty span of ``basis``.

    Returns the new basis (polynomial part only for a rational one; see
    :func:`refine_basis`) and ``T`` with ``N_old = N_new T`` on the domain.
    """
    if isinstance(basis, RationalBasis):
        basis = basis.basis
    if isinstance(basis, BSplineBasis):
        fine = BSplineBasis(basis.degree, basis.cells * (k + 1), basis.length, basis.kind)
        return fine, _projection(basis, fine)
    breaks = basis.breaks
    new = (breaks[:-1, None] + np.diff(breaks)[:, None] * np.arange(1, k + 1) / (k + 1)).ravel()
    knots, T = np.asarray(basis.knots, dtype=float), np.eye(basis.size)
    for x in new:                      # one pass over the rows of T per inserted knot
        knots, T = boehm_insert(knots, basis.degree, float(x), T)
    return KnotVectorBasis(basis.degree, knots), T


def elevate_degree(basis: Basis, p: int, direction: str = "u"
                   ) -> tuple[Basis, NDArray[np.float64]]:
    """The basis of degree ``n + p`` on the same breaks and continuity, and ``T``.

    Each distinct knot's multiplicity rises by ``p`` (clamped ends: ``n + p + 1``); ``T``
    comes from collocation at the new Greville points (see the module docstring).
    """
    if isinstance(basis, RationalBasis):
        basis = basis.basis
    if isinstance(basis, BSplineBasis) and basis.periodic:
        raise InputError(f"degree elevation is not defined in the periodic layout (direction "
                         f"{direction}): the elevated periodic splines have knots of "
                         "multiplicity p + 1; use an open or uniform layout to elevate")
    n, t = basis.degree, np.asarray(basis.knots, dtype=float)
    lo, hi = 0.0, basis.length      # a surface's domain starts at 0
    inner = t[(t > lo) & (t < hi)]
    values, counts = np.unique(inner, return_counts=True)
    knots = np.concatenate([np.full(n + p + 1, lo), np.repeat(values, counts + p),
                            np.full(n + p + 1, hi)])
    high = KnotVectorBasis(n + p, knots)
    xi = np.clip(high.greville(), lo, hi)
    return high, np.linalg.solve(high(xi), basis(xi))


def _projection(old: Basis, new: Basis) -> NDArray[np.float64]:
    """``T`` with ``N_new T = N_old``: least squares at ``n + 1`` Gauss points per new cell."""
    x, _ = gauss_points(new, new.degree + 1)
    T, *_ = np.linalg.lstsq(new(x), old(x), rcond=None)
    return T


def refine_basis(basis: Basis, elevate: int = 0, insert: int = 0, direction: str = "u"
                 ) -> tuple[Basis, NDArray[np.float64], NDArray[np.float64] | None]:
    """Elevate by ``elevate`` degrees, then insert ``insert`` knots into every span.

    Returns the new basis, ``T`` and, for a rational basis, the new weights ``a' = T a``
    (the returned basis is then the :class:`RationalBasis` on them).
    """
    for name, value, top in (("elevate", elevate, MAX_ELEVATE), ("refine", insert, MAX_INSERT)):
        if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 0:
            raise InputError(f"{name} in {direction} must be an integer >= 0, got {value!r}")
        if value > top:
            raise InputError(f"{name} in {direction} is {value}; at most {top}")
    size = (basis.cells * (insert + 1) + basis.degree + elevate
            + elevate * (basis.cells - 1) * (not getattr(basis, "periodic", False)))
    if size > MAX_SIZE:
        raise InputError(f"refining direction {direction} (elevate {elevate}, refine {insert}) "
                         f"gives about {size} functions from {basis.size}; at most {MAX_SIZE}")
    new: Basis = basis
    T = np.eye(basis.size)
    if elevate:
        new, step = elevate_degree(new, elevate, direction)
        T = step @ T
    if insert:
        new, step = insert_knots(new, insert)
        T = step @ T
    if not isinstance(basis, RationalBasis):
        return new, T, None
    weights = T @ basis.weights
    polynomial = new.basis if isinstance(new, RationalBasis) else new
    return RationalBasis(polynomial, weights), T, weights


def refine_surface(surface: Surface, elevate: tuple[int, int] = (0, 0),
                   insert: tuple[int, int] = (0, 0)) -> Surface:
    """The same surface on refined bases: degrees raised by ``elevate = (p_u, p_v)``, then
    ``insert = (k_u, k_v)`` knots put at equal distances into every span.

    Each direction maps the net as ``P' = T (a P) / a'`` (``a = 1`` for a polynomial
    direction; see the module docstring); the geometry is unchanged up to round-off.
    """
    P = np.asarray(surface.control_points, dtype=float)
    if surface.net_weights is not None:     # general weights: the homogeneous net (w P, w)
        P = np.concatenate([P * surface.net_weights[..., None],
                            surface.net_weights[..., None]], axis=-1)
    bases = []
    for axis, (name, basis) in enumerate((("u", surface.basis_u), ("v", surface.basis_v))):
        new, T, weights = refine_basis(basis, elevate[axis], insert[axis], name)
        a = basis.weights if isinstance(basis, RationalBasis) else np.ones(basis.size)
        shape = [1, 1, 1]
        shape[axis] = -1
        moved = np.moveaxis(np.tensordot(T, np.moveaxis(P * a.reshape(shape), axis, 0), 1),
                            0, axis)
        P = moved / (np.ones(new.size) if weights is None else weights).reshape(shape)
        bases.append(new)
    if surface.net_weights is not None:
        return Surface(P[..., :3] / P[..., 3:], bases[0], bases[1], name=surface.name,
                       net_weights=P[..., 3], orientation=surface.orientation)
    return Surface(P, bases[0], bases[1], name=surface.name, orientation=surface.orientation)
