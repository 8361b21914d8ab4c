"""Bézier pieces of plane curves: fitted to a curve given point by point, joined into loops.

A piece of degree ``n`` is ``γ(τ) = Σ_{a=0}^{n} b_a B^n_a(τ)``, ``τ ∈ [0, 1]``, with the
Bernstein polynomials ``B^n_a(τ) = C(n, a) τ^a (1 - τ)^{n-a}``. :func:`fit_pieces`
interpolates a curve ``f(t)`` on ``[t_0, t_1]`` at the ``n + 1`` Chebyshev–Lobatto
points ``τ_j = (1 - cos(π j / n)) / 2`` (the ends included, so neighbouring pieces meet
where ``f`` does) and checks the interpolant against ``f`` at ``3n`` points between
them; a piece off by more than the tolerance is halved, until it is not. A polynomial
``f`` of degree ``<= n`` on each given interval is reproduced exactly (up to round-off);
a rational or otherwise smooth one converges like ``ρ^{-n}`` (``ρ`` the Bernstein ellipse
of its nearest pole), so halving a piece gains a factor ``2^n`` or more.

This module imports numpy only: the CAD readers' child process runs it.
"""

from __future__ import annotations

from math import comb
from typing import Callable

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError

#: degree of the pieces fitted to a rational or non-polynomial curve
FIT_DEGREE = 9
#: most halvings of one interval before the curve counts as not smooth enough
MAX_HALVINGS = 16


def bernstein(degree: int, tau: NDArray[np.float64]) -> NDArray[np.float64]:
    """``B[..., a] = B^n_a(τ)`` for ``τ`` of any shape."""
    tau = np.asarray(tau, dtype=float)[..., None]
    a = np.arange(degree + 1)
    c = np.array([comb(degree, k) for k in a], dtype=float)
    return c * tau ** a * (1.0 - tau) ** (degree - a)


def bernstein_to_power(degree: int) -> NDArray[np.float64]:
    """``M[e, a]``: coefficient of ``τ^e`` in ``B^n_a(τ)``,
    ``C(n, a) C(n - a, e - a) (-1)^{e - a}`` for ``e >= a``, else 0."""
    n = degree
    M = np.zeros((n + 1, n + 1))
    for a in range(n + 1):
        for e in range(a, n + 1):
            M[e, a] = comb(n, a) * comb(n - a, e - a) * (-1) ** (e - a)
    return M


def lobatto(degree: int) -> NDArray[np.float64]:
    """Chebyshev–Lobatto points ``(1 - cos(π j / n)) / 2`` on ``[0, 1]``, ``j = 0..n``."""
    return 0.5 * (1.0 - np.cos(np.pi * np.arange(degree + 1) / degree))


def interpolate(values: NDArray[np.float64], degree: int) -> NDArray[np.float64]:
    """Bézier points ``(..., n + 1, 2)`` of the pieces through ``values`` ``(..., n + 1, 2)``
    taken at :func:`lobatto` points."""
    return np.linalg.solve(bernstein(degree, lobatto(degree)), values)


def evaluate(pieces: NDArray[np.float64], tau: NDArray[np.float64]) -> NDArray[np.float64]:
    """Points of every piece ``(K, n + 1, 2)`` at local parameters ``tau`` ``(q,)``:
    shape ``(K, q, 2)``."""
    return np.einsum("qa,kad->kqd", bernstein(pieces.shape[1] - 1, tau), pieces)


def elevate(pieces: NDArray[np.float64], degree: int) -> NDArray[np.float64]:
    """The same pieces as Bézier pieces of a higher ``degree`` (sampled and interpolated:
    exact up to round-off)."""
    if pieces.shape[1] - 1 == degree:
        return pieces
    return interpolate(evaluate(pieces, lobatto(degree)), degree)


def fit_pieces(curve: Callable[[NDArray[np.float64]], NDArray[np.float64]],
               breaks: NDArray[np.float64], degree: int, tol: float,
               source: str = "trim curve") -> NDArray[np.float64]:
    """Bézier pieces ``(K, n + 1, 2)`` within ``tol`` of ``curve`` on ``[breaks[0], breaks[-1]]``.

    ``curve(t)`` maps parameters ``(m,)`` to points ``(m, 2)``; ``breaks`` (increasing, or
    decreasing to run the curve backwards) are where it may lose smoothness (knots). Each
    interval is fitted with degree ``degree`` first; where that is off by more than ``tol``
    (at ``3 n`` check points), with :data:`FIT_DEGREE` and halving (see the module
    docstring). Raises ``InputError`` naming ``source`` if :data:`MAX_HALVINGS` do not do.
    """
    breaks = np.asarray(breaks, dtype=float)
    if breaks.size < 2 or np.any(np.diff(breaks) == 0):
        raise InputError(f"{source}: an empty parameter interval {breaks.tolist()}")
    out: list[NDArray[np.float64]] = []
    todo = [(float(a), float(b), degree, 0) for a, b in zip(breaks[:-1], breaks[1:])]
    while todo:
        lo, hi, n, depth = todo.pop(0)
        check = np.linspace(0.0, 1.0, 3 * n + 2)[1:-1]
        tau = np.concatenate([lobatto(n), check])
        values = np.asarray(curve(lo + (hi - lo) * tau), dtype=float)
        if values.shape != (tau.size, 2) or not np.all(np.isfinite(values)):
            raise InputError(f"{source}: its points near t = {lo:.9g} are not finite (u, v)")
        piece = interpolate(values[:n + 1], n)
        error = np.abs(bernstein(n, check) @ piece - values[n + 1:]).max()
        if error <= tol:
            out.append(piece[None])
        elif depth >= MAX_HALVINGS:
            raise InputError(f"{source}: no piece of degree {n} comes within {tol:.3g} of the "
                             f"curve near t = {lo:.9g} (off by {error:.3g}); the curve is not "
                             "smooth there")
        else:
            m = 0.5 * (lo + hi)
            halves = [(lo, m), (m, hi)] if n == FIT_DEGREE else [(lo, hi)]
            todo[:0] = [(a, b, FIT_DEGREE, depth + (n == FIT_DEGREE)) for a, b in halves]
    top = max(p.shape[1] - 1 for p in out)
    return np.concatenate([elevate(p, top) for p in out])


def join_loop(trims: list[NDArray[np.float64]], gap_tol: float, source: str
              ) -> NDArray[np.float64]:
    """The pieces of consecutive trims ``(K_i, n_i + 1, 2)`` as one closed loop
    ``(K, n + 1, 2)`` of the highest degree; each joint (the last trim's end with the first's
    start too) is set to the midpoint of the two ends, which must lie within ``gap_tol``."""
    top = max(t.shape[1] - 1 for t in trims)
    pieces = np.concatenate([elevate(t, top) for t in trims])
    ends, starts = pieces[:, -1], np.roll(pieces[:, 0], -1, axis=0)
    gap = np.hypot(*(ends - starts).T)
    if gap.max() > gap_tol:
        k = int(np.argmax(gap))
        raise InputError(f"{source}: the loop is open: piece {k} ends at {ends[k].tolist()}, "
                         f"{gap[k]:.3g} from where the next begins ({starts[k].tolist()}; "
                         f"tolerance {gap_tol:.3g})")
    joint = 0.5 * (ends + starts)
    pieces[:, -1] = joint
    pieces[:, 0] = np.roll(joint, 1, axis=0)
    return pieces
