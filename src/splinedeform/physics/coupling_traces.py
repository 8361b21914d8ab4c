"""Traces of patches on a coupling line: values and conormal slopes at quadrature points.

A line ``Γ`` where two sides meet is an edge of a patch or a ``C^0`` knot line inside one
(:mod:`splinedeform.physics.coupling`). On each side, the held parameter's basis is taken
from inside that side (:func:`splinedeform.knots.one_sided`), the basis along the line at
the quadrature points, and the rest geometry gives the conormal and the length ``ds``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray

from ..errors import InputError
from ..knots import one_sided
from ..rational import rational_operators
from ..surface import Surface

Array = NDArray[np.float64]

EXTRA_POINTS = 2
"""Gauss points per span beyond the ``max(p_a, p_b) + 1`` that integrate the products exactly."""
GAP_TOLERANCE = 1e-3
"""Largest distance, relative to the patches' size, between the two rest edges at a quadrature
point. Edges drawn separately differ by their fit errors (1e-5 for two cubic fits of one
circular arc); edges that do not belong together, or a reversal left out, by far more."""


@dataclass(frozen=True)
class Trace:
    """One side on ``Q`` points of a line: ``values`` ``V`` (``d`` there) and ``slopes``
    ``Dn`` (outward conormal derivatives ``∂_n d``) as ``(Q, n_u n_v)`` operators on the net;
    the rest ``points``, the line's ``speed`` ``|x_s|``, its unit ``tangent`` ``x_s / |x_s|``
    and the unit outward ``conormal``, each ``(Q, 3)`` (the speed ``(Q,)``)."""

    values: sp.csr_matrix
    slopes: sp.csr_matrix
    points: Array
    speed: Array
    tangent: Array
    conormal: Array


def trace_of(V: sp.csr_matrix, Df: sp.csr_matrix, Dr: sp.csr_matrix, P: Array, outward: int
             ) -> Trace:
    """The :class:`Trace` of a side from its operators on the net ``P`` ``(N, 3)``: values
    ``V``, derivatives across (``Df``) and along (``Dr``) the line.

    The conormal is ``n ∝ x_f − (x_f·x_r / x_r·x_r) x_r``, so
    ``∂_n d = ±(d_f − c d_r) / |x_f − c x_r|``, the sign ``outward``.
    """
    x, x_f, x_r = V @ P, Df @ P, Dr @ P
    c = np.einsum("qi,qi->q", x_f, x_r) / np.einsum("qi,qi->q", x_r, x_r)
    across_line = x_f - c[:, None] * x_r
    length = np.linalg.norm(across_line, axis=1)
    Dn = sp.diags(outward / length) @ (Df - sp.diags(c) @ Dr)
    speed = np.linalg.norm(x_r, axis=1)
    return Trace(V, Dn.tocsr(), x, speed, x_r / speed[:, None],
                 outward * across_line / length[:, None])


@dataclass(frozen=True)
class Side:
    """One side of a coupling line: ``surface`` near the line ``fixed = value``.

    ``fixed`` is the parameter held (``"u"``: the line runs along v), ``outward`` the sign of
    the held parameter's direction pointing out of the side (``+1``: the side lies below
    ``value``). The basis across the line is evaluated from inside the side (its one-sided
    limit at a ``C^0`` knot).
    """

    surface: Surface
    fixed: str
    value: float
    outward: int

    @classmethod
    def of_edge(cls, surface: Surface, edge: str) -> Side:
        """The side of ``surface`` at its edge ``"u0" | "u1" | "v0" | "v1"``."""
        (_, lu), (_, lv) = surface.domain
        fixed, end = edge[0], edge[1]
        length = lu if fixed == "u" else lv
        return cls(surface, fixed, 0.0 if end == "0" else length, -1 if end == "0" else 1)

    @property
    def running(self):
        """The basis along the line."""
        return self.surface.basis_v if self.fixed == "u" else self.surface.basis_u

    @property
    def breaks(self) -> Array:
        """Knot span ends of the running basis."""
        basis = self.running
        breaks = getattr(basis, "breaks", None)
        return np.arange(basis.cells + 1) * basis.h if breaks is None else np.asarray(breaks)

    def traces(self, s: Array) -> Trace:
        """The side's :class:`Trace` at running parameters ``s`` (shape ``(Q,)``).

        With ``f`` the held and ``r`` the running parameter, the conormal is
        ``n ∝ x_f − (x_f·x_r / x_r·x_r) x_r``, so ``∂_n d = ±(d_f − c d_r) / |x_f − c x_r|``.
        """
        surface = self.surface
        across = surface.basis_u if self.fixed == "u" else surface.basis_v
        i_f, b_f = one_sided(across, self.value, -self.outward, 1)      # (2, n_f + 1)
        i_r, b_r = self.running.nonzero_derivatives(s, 1)               # (2, Q, n_r + 1)
        n_v = surface.basis_v.size
        if self.fixed == "u":
            cols = i_f[None, :, None] * n_v + i_r[:, None, :]
        else:
            cols = i_r[:, :, None] * n_v + i_f[None, None, :]

        def operator(j_f: int, j_r: int) -> sp.csr_matrix:
            if self.fixed == "u":
                values = b_f[j_f][None, :, None] * b_r[j_r][:, None, :]
            else:
                values = b_r[j_r][:, :, None] * b_f[j_f][None, None, :]
            rows = np.broadcast_to(np.arange(s.size)[:, None, None], values.shape)
            return sp.csr_matrix((values.ravel(), (rows.ravel(), cols.ravel())),
                                 shape=(s.size, surface.shape[0] * n_v))

        V, Df, Dr = operator(0, 0), operator(1, 0), operator(0, 1)
        if surface.net_weights is not None:          # general weights: the quotient rule
            V, (Df, Dr) = rational_operators(V, (Df, Dr), surface.net_weights)
        return trace_of(V, Df, Dr, surface.control_points.reshape(-1, 3), self.outward)

    def points(self) -> int:
        """Gauss points per span along the line: ``n + 1 +`` :data:`EXTRA_POINTS`, or a
        rational basis' own (its functions are not polynomials)."""
        running = self.running
        return max(running.degree + 1 + EXTRA_POINTS, getattr(running, "points_per_cell", 0))

    def element_size(self) -> float:
        """Mean length of the line's knot spans on the rest surface, ``h = |Γ| / spans``."""
        breaks = self.breaks
        s, w = gauss(breaks, self.points())
        return float(w @ self.traces(s).speed) / (breaks.size - 1)


def gauss(breaks: Array, points: int) -> tuple[Array, Array]:
    """Gauss–Legendre points and weights, ``points`` on every span between ``breaks``."""
    ref_x, ref_w = np.polynomial.legendre.leggauss(points)
    left, width = breaks[:-1, None], np.diff(breaks)[:, None]
    return (left + 0.5 * width * (ref_x + 1.0)).ravel(), (0.5 * width * ref_w).ravel()


def union(first: Array, second: Array, tol: float = 1e-12) -> Array:
    """Sorted union of two break sets on ``[0, 1]``, breaks closer than ``tol`` merged."""
    joined = np.sort(np.concatenate([first, second]))
    return joined[np.concatenate([[True], np.diff(joined) > tol])]


@dataclass(frozen=True)
class Line:
    """Both sides' traces at common quadrature points of ``Γ`` and the weights ``ds``.

    ``sides`` are the two :class:`Trace` (columns of each side's own net); ``projector`` is
    the finer side's running basis at the points, ``(Q, n_r)``, the space a jump is measured
    in, and ``mirrored`` whether its functions run against ``a``'s parameter.
    """

    sides: tuple[Trace, Trace]
    weights: Array
    projector: sp.csr_matrix
    mirrored: bool

    def space(self, crosspoints: int | tuple[int, int]) -> sp.csr_matrix:
        """The projection's basis with ``crosspoints`` (at ``a``'s start, end) merged."""
        start, end = (crosspoints, crosspoints) if np.ndim(crosspoints) == 0 else crosspoints
        return merged(self.projector, *((end, start) if self.mirrored else (start, end)))


def common_line(side_a: Side, side_b: Side, reversed_: bool, where: str) -> Line:
    """The traces of both sides on ``Γ``.

    On ``σ ∈ [0, 1]``: ``s_a = L_a σ`` and ``s_b = L_b σ`` (``L_b (1 − σ)`` if reversed),
    ``ds = |x_{a,s}| L_a dσ``, Gauss points on the union of both edges' spans. Raises where
    the two rest edges do not coincide.
    """
    lo_a, hi_a = side_a.breaks[[0, -1]]
    lo_b, hi_b = side_b.breaks[[0, -1]]
    unit_a = (side_a.breaks - lo_a) / (hi_a - lo_a)
    unit_b = (side_b.breaks - lo_b) / (hi_b - lo_b)
    breaks = union(unit_a, 1.0 - unit_b if reversed_ else unit_b)
    sigma, w = gauss(breaks, max(side_a.points(), side_b.points()))
    s_a = lo_a + (hi_a - lo_a) * sigma
    s_b = lo_b + (hi_b - lo_b) * ((1.0 - sigma) if reversed_ else sigma)
    trace_a, trace_b = side_a.traces(s_a), side_b.traces(s_b)
    check_meet((trace_a, trace_b), (side_a.surface, side_b.surface), s_a,
               f"{where}: the two edges do not meet; at s = {{at}} of the first",
               "Check the edges and whether one is reversed")
    # the finer edge's splines (more functions; a's on a tie), ends in a's order
    fine_b = side_b.running.size > side_a.running.size
    projector = side_b.running.matrix(s_b) if fine_b else side_a.running.matrix(s_a)
    return Line((trace_a, trace_b), w * trace_a.speed * (hi_a - lo_a), projector.tocsr(),
                fine_b and reversed_)


def check_meet(traces: tuple[Trace, Trace], surfaces: tuple[Surface, Surface], s: Array,
               what: str, advice: str = "") -> None:
    """Raise where the two sides' rest points lie farther apart than :data:`GAP_TOLERANCE`
    of the two surfaces' size; ``what`` names the place, ``{at}`` the worst parameter
    among ``s``."""
    points = np.concatenate([x.control_points.reshape(-1, 3) for x in surfaces])
    size = float(np.ptp(points, axis=0).max())
    gap = np.linalg.norm(traces[0].points - traces[1].points, axis=1)
    if gap.max() > GAP_TOLERANCE * size:
        worst = int(gap.argmax())
        raise InputError(
            f"{what.format(at=f'{s[worst]:.6g}')} they are {gap[worst]:.3g} apart "
            f"({gap[worst] / size:.2g} of the surfaces' size, more than {GAP_TOLERANCE:g})"
            + (f". {advice}" if advice else ""))


def merged(basis: sp.csr_matrix, start: int, end: int) -> sp.csr_matrix:
    """The trace space with its first ``start`` and last ``end`` functions added to their
    neighbour (the crosspoint modification of mortar methods; the sum stays one).

    ``basis`` holds the functions at the quadrature points, ``(Q, n)``; the result has
    ``n − start − end`` columns.
    """
    n = basis.shape[1]
    if min(start, end) < 0 or n <= start + end:
        raise InputError(f"cannot merge {start} and {end} end functions of a trace space of {n}")
    target = np.clip(np.arange(n), start, n - 1 - end)
    keep = np.unique(target)
    S = sp.csr_matrix((np.ones(n), (np.arange(n), np.searchsorted(keep, target))),
                      shape=(n, keep.size))
    return (basis @ S).tocsr()


