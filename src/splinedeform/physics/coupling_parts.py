"""The trace space of a shared stretch of two edges, and the kinks it must follow.

Along a stretch ``[t_0, t_1]`` of ``a``'s curve (:mod:`.coupling_curves`, sides with a
part) the displacement jump ``d_a − d_b`` is penalised after its ``L²`` projection onto
B-splines of degree ``n`` (the finer side's) on ``[t_0, t_1]``, open at both ends, with
a simple knot at each of the finer side's knot-line crossings: that side's trace space,
exactly where its curve is straight in its parameters (the mortar method's choice of the
finer side's space, :func:`stretch_space`). A side's trace is only ``C^0``
where its curve crosses a ``C^0`` knot line of its face (a knot repeated as often as the
degree: the joints of a CAD circle's rational quadratic arcs, :func:`~.coupling.c0_lines`);
a smooth trace space cannot follow the jump's kink there, and what it misses is left
unpenalised, whatever the penalty factor. So each such crossing (of either side, ``b``'s
mapped onto ``a``'s curve) is a knot of multiplicity ``n`` of the trace space, replacing
the crossings within :data:`MERGE` of a mean span of it. Where one side is an iso-edge,
its own running basis is the space (:func:`running_space`).
"""

from __future__ import annotations

from typing import Any, Sequence

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray

from ..knots import KnotVectorBasis
from ..trim.loops import CircleLoop, PolygonLoop
from .coupling import c0_lines

Array = NDArray[np.float64]
MERGE = 0.25
"""A crossing closer to a kink than this fraction of a mean span is replaced by it."""
SEAM = 1e-9
"""Ends of an edge closer than this (relative to its face's size) are one point, a seam."""


def crossings(loop: Any, lines: tuple[Sequence[float], Sequence[float]]) -> Array:
    """Parameters in ``[0, T)`` (:func:`~.coupling_curves.period`) where a loop crosses the
    lines ``u = c`` (``lines[0]``) and ``v = c`` (``lines[1]``): on a circle
    ``c + r (cos θ, sin θ)`` at ``θ = ± arccos((c − c_u) / r)`` and
    ``θ = arcsin((c − c_v) / r), π − arcsin(…)``; on a polygon's edge ``k`` at
    ``k + (c − a_k) / (b_k − a_k)``; on a spline loop's span the roots of its polynomial."""
    found: list[Array] = [np.zeros(0)]
    if isinstance(loop, CircleLoop):
        for axis, values in enumerate(lines):
            x = (np.asarray(values, dtype=float) - loop.centre[axis]) / loop.radius
            x = x[np.abs(x) <= 1.0]
            if axis == 0:
                found += [np.arccos(x), -np.arccos(x)]
            else:
                found += [np.arcsin(x), np.pi - np.arcsin(x)]
        return np.mod(np.concatenate(found), 2.0 * np.pi)
    if isinstance(loop, PolygonLoop):
        a = loop.vertices
        d = np.roll(a, -1, axis=0) - a
        for axis, values in enumerate(lines):
            values = np.asarray(values, dtype=float)
            with np.errstate(divide="ignore", invalid="ignore"):
                tau = (values[None] - a[:, axis, None]) / d[:, axis, None]
            k, j = np.nonzero((tau >= 0) & (tau < 1))
            found.append(k + tau[k, j])
        return np.concatenate(found)
    for axis, values in enumerate(lines):
        for value in values:
            span, tau = loop.crossings(axis, float(value))
            found.append(span + tau)
    return np.concatenate(found)


def kinks(side: Any) -> Array:
    """Parameters inside a side's part where its curve crosses a ``C^0`` knot line of its
    face (module docstring), sorted."""
    from .coupling_curves import period

    lines = c0_lines(side.surface)
    if not lines or side.part is None:
        return np.zeros(0)
    t = crossings(side.loop, tuple([k for d, k in lines if d == axis] for axis in "uv"))
    T = period(side.loop)
    lo, hi = side.part
    every = (t[None, :] + T * np.arange(np.floor(lo / T) - 1, np.ceil(hi / T) + 1)[:, None])
    every = every.ravel()
    span = hi - lo
    return np.sort(every[(every > lo + 1e-9 * span) & (every < hi - 1e-9 * span)])


def stretch_space(t: Array, part: tuple[float, float], breaks: Array, degree: int,
                  corners: Array) -> sp.csr_matrix:
    """The trace space at ``t`` (module docstring): open B-splines of ``degree`` on
    ``part`` with a simple knot at each of the finer side's ``breaks`` inside it (its
    knot-line crossings, in ``a``'s parameter) and a knot of multiplicity ``degree`` at
    each of ``corners`` (kinks in ``a``'s parameter)."""
    lo, hi = part
    tol = 1e-9 * (hi - lo)
    inner = np.unique(np.asarray(breaks, dtype=float))
    inner = inner[(inner > lo + tol) & (inner < hi - tol)]
    width = (hi - lo) / (inner.size + 1)
    corners = np.asarray(corners, dtype=float)
    if corners.size:
        corners = np.unique(np.round(corners / tol) * tol)
        near = np.abs(inner[:, None] - corners[None]).min(axis=1) < MERGE * width
        inner = inner[~near]
    knots = np.sort(np.concatenate([np.full(degree + 1, lo), inner,
                                    np.repeat(corners, degree), np.full(degree + 1, hi)]))
    return KnotVectorBasis(degree, knots).matrix(np.clip(t, lo, hi)).tocsr()


def running_space(side: Any, t: Array) -> sp.csr_matrix:
    """The running basis of an iso-edge side at its curve parameters ``t``: the face's
    ``u`` basis along ``v0`` / ``v1`` (where the rectangle's polygon runs along ``u``),
    its ``v`` basis along ``u0`` / ``u1``, the functions that vanish on the stretch
    dropped (the other side's trace is measured in this one's own space, as on a
    non-conforming iso-edge). A whole edge that closes on itself (a cylinder's circle,
    whose two ends are merged at the seam) has its first and last functions summed: the
    merged net's trace space, so that the projected jump can vanish there too."""
    from .coupling_curves import curve_points

    p, d = curve_points(side.loop, t)
    along_u = np.abs(d[:, 0]).mean() >= np.abs(d[:, 1]).mean()
    basis = side.surface.basis_u if along_u else side.surface.basis_v
    x = np.clip(p[:, 0 if along_u else 1], 0.0, basis.length)
    matrix = basis.matrix(x).tocsc()
    used = np.flatnonzero(np.abs(matrix).sum(axis=0).A1 > 0)
    space = matrix[:, used].tocsc()
    lo, hi = side.bounds()
    ends = side.position(np.array([lo, hi]))[0]
    size = float(np.ptp(side.surface.control_points.reshape(-1, 3), axis=0).max())
    whole = abs(hi - lo - 1.0) < 1e-9 and used[0] == 0 and used[-1] == basis.size - 1
    if whole and np.linalg.norm(ends[1] - ends[0]) <= SEAM * size and space.shape[1] > 2:
        glued = space[:, :1] + space[:, -1:]
        space = sp.hstack([glued, space[:, 1:-1]], format="csc")
    return space.tocsr()
