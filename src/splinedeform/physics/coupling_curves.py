"""Coupling lines along curves: trim edges where two faces meet.

An iso-edge (:mod:`.coupling_traces`) is the special case of a straight curve in a face's
parameters. Here each side is a face with a curve ``γ(t) = (u(t), v(t))`` in its parameter
rectangle (a trim loop, :mod:`splinedeform.trim.loops`), and the two faces' curves trace one
curve ``Γ`` in space. With the curve's tangent ``γ' = (u', v')`` and its right-hand normal
``ν = (v', −u')`` in the parameter plane, the derivatives along and across the curve are

.. math:: d_r = u' d_u + v' d_v, \\qquad d_f = v' d_u − u' d_v,

and, as on an iso-edge, the outward conormal slope is
``∂_n d = ± (d_f − c d_r) / |x_f − c x_r|``, ``c = x_f · x_r / x_r · x_r`` (the sign makes
``n`` point out of the face's trimmed region). On the iso-edge ``u = L`` run upwards,
``γ' = (0, 1)`` and ``ν = (1, 0)``: the held direction ``f = u``, the running one ``r = v``,
which is :meth:`.coupling_traces.Side.traces`.

**Quadrature** (Herrema et al., CMAME 346, 2019; PENGoLINS): Gauss points on the pieces of
``a``'s curve between its crossings of ``a``'s knot lines and of ``b``'s (``b``'s crossings
mapped onto ``a``'s curve), :data:`~.coupling_traces.EXTRA_POINTS` more than the degree
needs; each point's parameters on ``b`` come from the closest point of ``b``'s curve to
``x_a(γ_a(t))`` (Newton's method on ``|x_b(γ_b(s)) − x|²`` from the nearest of a dense
sample), so the two faces' curves need not share a parameter. ``ds = |x_{a,t}| dt``.

**Trace space** of the projected (mortar) penalty: B-splines of the finer side's degree in
``a``'s curve parameter, periodic on a closed curve, with as many spans as the finer side's
curve has pieces between knot lines (its element size along ``Γ``).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Sequence

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray

from ..basis import BSplineBasis
from ..body.interface import TrimInterface
from ..errors import InputError
from ..material import Material
from ..rational import rational_operators
from ..surface import Surface
from ..trim.cells import Grid, _circle_pieces
from ..trim.loops import CircleLoop, PolygonLoop
from ..trim.spline_loop import SplineLoop
from ..trim.values import tensor_values
from .coupling import line_penalty, penalty_factors, shell_line_penalty
from .coupling_parts import kinks, running_space, stretch_space
from .shell import ShellMaterial
from .coupling_traces import (EXTRA_POINTS, Line, Trace, check_meet, gauss, trace_of,
                              union)

Array = NDArray[np.float64]
NEWTON_STEPS = 30
"""Most Newton steps of the closest-point projection onto a curve (it converges
quadratically from the nearest of :data:`SAMPLES_PER_PIECE` samples per piece)."""
SAMPLES_PER_PIECE = 8
"""Samples per piece of a curve from which the projection starts."""


def period(loop: Any) -> float:
    """Parameter length of a closed curve: ``2π`` for a circle (angle), the number of
    edges of a polygon (``t = k + τ`` on edge ``k``), the number of spans of a spline loop."""
    if isinstance(loop, CircleLoop):
        return 2.0 * np.pi
    if isinstance(loop, PolygonLoop):
        return float(len(loop.vertices))
    if isinstance(loop, SplineLoop):
        return float(loop.spans)
    raise InputError(f"a coupling curve is a circle, polygon or spline loop, got "
                     f"{type(loop).__name__}")


def curve_points(loop: Any, t: Array) -> tuple[Array, Array]:
    """Points ``γ(t)`` and tangents ``γ'(t)`` in the face's parameters, ``(Q, 2)`` each."""
    t = np.mod(np.asarray(t, dtype=float), period(loop))
    if isinstance(loop, CircleLoop):
        c, r = np.asarray(loop.centre), loop.radius
        ring = np.stack([np.cos(t), np.sin(t)], axis=-1)
        return c + r * ring, r * np.stack([-ring[:, 1], ring[:, 0]], axis=-1)
    if isinstance(loop, PolygonLoop):
        a = loop.vertices
        b = np.roll(a, -1, axis=0)
        k = np.minimum(t.astype(int), len(a) - 1)
        tau = (t - k)[:, None]
        return a[k] + tau * (b[k] - a[k]), b[k] - a[k]
    return loop.evaluate(t)


def curve_breaks(loop: Any, lengths: tuple[float, float], cells: tuple[int, int]) -> Array:
    """Parameters in ``[0, period]`` where the curve crosses a knot line of a grid of
    ``cells`` equal cells on ``[0, L_u] × [0, L_v]``, its own joints (polygon vertices,
    spline joints) and both ends included, sorted."""
    lines = [np.arange(m + 1) * (L / m) for L, m in zip(lengths, cells)]
    T = period(loop)
    if isinstance(loop, CircleLoop):
        lo, hi = _circle_pieces(CircleLoop(loop.centre, loop.radius), Grid(cells, lengths))
        found = [np.mod(np.concatenate([lo, hi]), T)]
    elif isinstance(loop, PolygonLoop):
        a = loop.vertices
        d = np.roll(a, -1, axis=0) - a
        found = [np.arange(len(a), dtype=float)]
        for axis in (0, 1):
            with np.errstate(divide="ignore", invalid="ignore"):
                tau = (lines[axis][None] - a[:, axis, None]) / d[:, axis, None]
            k, j = np.nonzero((tau > 0) & (tau < 1))
            found.append(k + tau[k, j])
    else:
        found = [np.arange(loop.spans, dtype=float)]
        for axis in (0, 1):
            for value in lines[axis]:
                span, tau = loop.crossings(axis, value)
                found.append(span + tau)
    inner = np.concatenate(found)
    return union(np.concatenate([[0.0, T], inner[(inner > 0) & (inner < T)]]) / T,
                 np.zeros(0)) * T


def _grid(surface: Surface) -> tuple[tuple[float, float], tuple[int, int]]:
    (_, lu), (_, lv) = surface.domain
    return (lu, lv), (surface.basis_u.cells, surface.basis_v.cells)


@dataclass(frozen=True)
class CurveSide:
    """One side of a coupling curve: ``surface`` along its curve ``loop`` (in ``(u, v)``).

    ``outward`` is ``+1`` when the face's region lies on the left of the curve's direction
    (so the right-hand normal ``ν`` points out of it), ``−1`` otherwise. ``part`` is the
    stretch ``[t_0, t_1]`` of the curve's parameter that the side covers (a trim edge, or
    the common part of two edges; ``t_1`` may pass the period of a closed curve), None for
    the whole closed curve.
    """

    surface: Surface
    loop: Any
    outward: int
    part: tuple[float, float] | None = None

    @classmethod
    def of_loop(cls, surface: Surface, loop: Any,
                part: tuple[float, float] | None = None) -> CurveSide:
        """The side with its ``outward`` sign found by testing a point just left of the curve
        against the face's region (its trim, or the parameter rectangle)."""
        from ..trim.surface_trim import region_contains
        t = curve_breaks(loop, *_grid(surface)) if part is None else \
            _within(curve_breaks(loop, *_grid(surface)), period(loop), part)
        mid = 0.5 * (t[:-1] + t[1:])
        p, d = curve_points(loop, mid)
        (_, lu), (_, lv) = surface.domain
        step = 1e-6 * float(np.hypot(lu, lv))
        left = p + step * np.stack([-d[:, 1], d[:, 0]], axis=-1) / np.hypot(*d.T)[:, None]
        inside = (region_contains(surface, left) if surface.trim is not None else
                  (left[:, 0] > 0) & (left[:, 0] < lu) & (left[:, 1] > 0) & (left[:, 1] < lv))
        return cls(surface, loop, 1 if np.mean(inside) >= 0.5 else -1, part)

    def bounds(self) -> tuple[float, float]:
        """``(t_0, t_1)``: the part, or ``(0, period)`` for the whole curve."""
        return (0.0, period(self.loop)) if self.part is None else self.part

    def breaks(self) -> Array:
        """Parameters where the curve crosses this face's knot lines (:func:`curve_breaks`),
        on the part only (its ends included) where the side has one."""
        every = curve_breaks(self.loop, *_grid(self.surface))
        return every if self.part is None else _within(every, period(self.loop), self.part)

    def points(self) -> int:
        """Gauss points per piece: ``n + 1 +`` :data:`EXTRA_POINTS` (the face's degree)."""
        return max(self.surface.basis_u.degree, self.surface.basis_v.degree) + 1 + EXTRA_POINTS

    def _operators(self, t: Array) -> tuple[Array, Array, sp.csr_matrix, sp.csr_matrix,
                                             sp.csr_matrix]:
        """Curve tangents and the operators ``V``, ``D_u``, ``D_v`` at parameters ``t``."""
        surface = self.surface
        p, d = curve_points(self.loop, t)
        (_, lu), (_, lv) = surface.domain
        p = np.clip(p, 0.0, [lu, lv])
        B = tensor_values((surface.basis_u, surface.basis_v), p, [(0, 0), (1, 0), (0, 1)])
        V, Du, Dv = B[(0, 0)], B[(1, 0)], B[(0, 1)]
        if surface.net_weights is not None:          # general weights: the quotient rule
            V, (Du, Dv) = rational_operators(V, (Du, Dv), surface.net_weights)
        return p, d, V.tocsr(), Du.tocsr(), Dv.tocsr()

    def position(self, t: Array) -> tuple[Array, Array]:
        """Rest points ``x(γ(t))`` and their derivatives ``d x(γ(t)) / dt``, ``(Q, 3)``."""
        _, d, V, Du, Dv = self._operators(t)
        P = self.surface.control_points.reshape(-1, 3)
        return V @ P, d[:, :1] * (Du @ P) + d[:, 1:] * (Dv @ P)

    def traces(self, t: Array) -> Trace:
        """The side's :class:`~.coupling_traces.Trace` at curve parameters ``t`` ``(Q,)``
        (module docstring for the conormal slope)."""
        _, d, V, Du, Dv = self._operators(t)
        Dr = sp.diags(d[:, 0]) @ Du + sp.diags(d[:, 1]) @ Dv
        Df = sp.diags(d[:, 1]) @ Du - sp.diags(d[:, 0]) @ Dv
        return trace_of(V, Df.tocsr(), Dr.tocsr(),
                        self.surface.control_points.reshape(-1, 3), self.outward)

    def closest(self, x: Array, start: Array | None = None) -> Array:
        """Curve parameters of the points of the curve closest to ``x`` ``(Q, 3)``:
        Gauss–Newton on ``g(t) = (X(t) − x) · X'(t) = 0`` from ``start`` or else the
        nearest sample; on a part, ``t`` is kept in it."""
        T = period(self.loop)
        t0 = self.breaks()
        lo, hi = self.bounds()
        if start is None:
            sample = np.append((t0[:-1, None] + np.diff(t0)[:, None]
                                * (np.arange(SAMPLES_PER_PIECE) / SAMPLES_PER_PIECE)).ravel(),
                               t0[-1])
            X, _ = self.position(sample)
            t = sample[np.argmin(((x[:, None, :] - X[None]) ** 2).sum(-1), axis=1)]
        else:
            t = np.asarray(start, dtype=float).copy()
        limit = 0.5 * (hi - lo) / max(len(t0) - 1, 1)
        for _ in range(NEWTON_STEPS):
            X, dX = self.position(t)
            step = np.einsum("qi,qi->q", X - x, dX) / np.einsum("qi,qi->q", dX, dX)
            step = np.clip(step, -limit, limit)
            t = np.mod(t - step, T) if self.part is None else np.clip(t - step, lo, hi)
            if np.max(np.abs(step), initial=0.0) <= 1e-14 * T:
                break
        return t


def _within(breaks: Array, T: float, part: tuple[float, float]) -> Array:
    """The breaks of a closed curve (on ``[0, T]``, repeated with its period) inside
    ``part``, and the part's two ends."""
    lo, hi = part
    turns = np.arange(np.floor(lo / T) - 1, np.ceil(hi / T) + 1)
    every = (breaks[None, :] + T * turns[:, None]).ravel()
    inner = every[(every > lo) & (every < hi)]
    return lo + union((np.concatenate([[lo, hi], inner]) - lo) / (hi - lo),
                      np.zeros(0), 1e-10) * (hi - lo)


def curve_line(side_a: CurveSide, side_b: CurveSide, where: str,
               start: Any = None, running: int | None = None) -> tuple[Line, float]:
    """Both sides' traces on ``Γ`` (module docstring) and the element size ``h`` along it
    (the smaller of the two sides' mean piece lengths). Raises where the two rest curves do
    not coincide.

    Sides with parts (two trim edges, or a trim edge and an iso-edge, meeting along a
    common stretch): Gauss points on ``a``'s part only, the trace space open B-splines on
    it (:func:`~.coupling_parts.stretch_space`); ``start(t)`` maps ``a``'s parameters to
    first guesses of ``b``'s (a monotone map of the part's ends,
    :func:`~splinedeform.body.trim_edges.common_parts`). ``running = 0`` or ``1`` names a
    side that is an iso-edge: the trace space is then its own running basis
    (:func:`~.coupling_parts.running_space`), the mortar choice of an iso-edge interface."""
    lo, hi = side_a.bounds()
    breaks_a = side_a.breaks()
    breaks_b = side_b.breaks()
    ends_b = breaks_b[:-1] if side_b.part is None else breaks_b
    Xb, _ = side_b.position(ends_b)
    guess = None if start is None else np.interp(ends_b, *_inverse(start, lo, hi))
    mapped = np.clip(side_a.closest(Xb, guess), lo, hi)
    breaks = lo + union((breaks_a - lo) / (hi - lo),
                        np.concatenate([[0.0, 1.0], np.sort(mapped - lo) / (hi - lo)]),
                        1e-9 if side_a.part is not None else 1e-12) * (hi - lo)
    t, w = gauss(breaks, max(side_a.points(), side_b.points()))
    trace_a = side_a.traces(t)
    s = side_b.closest(trace_a.points, None if start is None else start(t))
    trace_b = side_b.traces(s)
    check_meet((trace_a, trace_b), (side_a.surface, side_b.surface), t,
               f"{where}: the two trim curves do not meet; at t = {{at}} of the first")
    weights = w * trace_a.speed
    length = float(weights.sum())
    pieces = (len(breaks_a) - 1, len(breaks_b) - 1)
    fine = side_b if pieces[1] > pieces[0] else side_a
    degree = max(fine.surface.basis_u.degree, fine.surface.basis_v.degree)
    spans = max(pieces)
    if running is not None:
        space = running_space((side_a, side_b)[running], (t, s)[running])
    elif side_a.part is None:
        space = BSplineBasis(degree, max(spans, degree + 1), hi, "periodic").matrix(t)
    else:
        corners = [kinks(side_a)]
        if len(kinks(side_b)):
            Xk = side_b.position(kinks(side_b))[0]
            corners.append(side_a.closest(Xk, None if start is None else
                                          np.interp(kinks(side_b), *_inverse(start, lo, hi))))
        own = breaks_a if fine is side_a else np.sort(mapped)
        space = stretch_space(t, (lo, hi), own, degree, np.concatenate(corners))
    return Line((trace_a, trace_b), weights, space.tocsr(), False), length / spans


def _inverse(start: Any, lo: float, hi: float) -> tuple[Array, Array]:
    """Samples ``(s, t)`` of the inverse of a monotone map ``s = start(t)`` on
    ``[lo, hi]``, increasing in ``s`` (for :func:`numpy.interp`)."""
    t = np.linspace(lo, hi, 17)
    s = np.asarray(start(t), dtype=float)
    return (s, t) if s[-1] >= s[0] else (s[::-1], t[::-1])


def loop_of(surface: Surface, index: int) -> Any:
    """Trim loop ``index`` of a face (0 the outer loop, then its holes)."""
    loops = () if surface.trim is None else surface.trim.loops
    if not 0 <= index < len(loops):
        raise InputError(f"face {surface.name!r} has {len(loops)} trim loop(s), no loop "
                         f"{index}")
    return loops[index]


def curve_penalty(patches: Sequence[Surface], interface: TrimInterface, material: Any,
                  offsets: Sequence[int]) -> sp.csr_matrix:
    """The coupling of two faces along a trim curve, every factor from the material and the
    mesh: ``½ α ∫_Γ |Π (d_a − d_b)|² ds`` and, where the energy bends,
    ``½ β ∫_Γ (Π (∂_{n_a} d_a + ∂_{n_b} d_b))² ds``, ``(α, β)`` of
    :func:`~.coupling.penalty_factors` at the element size of :func:`curve_line`;
    the same matrices as an iso-edge's (:func:`~.coupling.line_penalty`), on the faces'
    concatenated control points (``offsets`` their first rows). For a Kirchhoff–Love shell
    (:class:`~splinedeform.physics.shell.ShellMaterial`) the displacement penalty on all
    three components and the rotation penalty ``½ β ∫_Γ (Π (θ_a − θ_b))² ds`` on its
    interleaved unknowns (:func:`~.coupling.shell_line_penalty`: ``θ`` the rotation of
    each face's conormal fibre about the tangent, so that a crease keeps its angle)."""
    for index in (interface.a, interface.b):
        if not 0 <= index < len(patches):
            raise InputError(f"{interface} names face {index}, but the body has "
                             f"{len(patches)} face(s)")
    sides = [CurveSide.of_loop(patches[p], loop_of(patches[p], k))
             for p, k in ((interface.a, interface.loop_a), (interface.b, interface.loop_b))]
    line, h = curve_line(sides[0], sides[1], str(interface))
    if not isinstance(material, ShellMaterial):
        return line_penalties(line, h, material, interface.a, interface.b, patches, offsets)
    alpha, beta = penalty_factors(material, h)
    size = int(offsets[-1]) + patches[-1].shape[0] * patches[-1].shape[1]
    layout = (int(offsets[interface.a]), int(offsets[interface.b]), size)
    return shell_line_penalty(line, layout, alpha, beta, line.space(0))


def line_penalties(line: Line, h: float, material: Material, a: int, b: int,
                   patches: Sequence[Surface], offsets: Sequence[int],
                   space: sp.csr_matrix | None = None) -> sp.csr_matrix:
    """The displacement penalty and, where the energy bends, the slope penalty of
    :func:`curve_penalty` on ``line`` between faces ``a`` and ``b``, at element size ``h``,
    in the trace space ``space`` (default the line's, no end merged)."""
    alpha, beta = penalty_factors(material, h)
    size = int(offsets[-1]) + patches[-1].shape[0] * patches[-1].shape[1]
    layout = (int(offsets[a]), int(offsets[b]), size)
    space = line.space(0) if space is None else space
    K = line_penalty(line, "values", layout, alpha, space)
    return K if beta == 0 else (K + line_penalty(line, "slopes", layout, beta, space)).tocsr()
