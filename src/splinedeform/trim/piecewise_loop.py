"""Closed loops of Bézier pieces in ``(u, v)``: the trim loops of CAD faces.

A CAD trim loop is a chain of trim curves, each a NURBS curve with its own knots and
weights. Here it is held as ``K`` polynomial Bézier pieces of one degree ``n`` run one
after the other (:mod:`splinedeform.trim.bezier`): piece ``s`` is
``γ_s(τ) = Σ_a b_{s,a} B^n_a(τ)`` for the loop parameter ``t = s + τ``, ``τ ∈ [0, 1]``,
and ``b_{s,n} = b_{s+1,0}`` (indices modulo ``K``). In power form
``γ_s(τ) = Σ_e C_{s,e} τ^e`` with ``C_{s,e} = Σ_a M_{e,a} b_{s,a}``
(:func:`~splinedeform.trim.bezier.bernstein_to_power`) it is exactly what a
:class:`~splinedeform.trim.spline_loop.SplineLoop` is span by span, so it is one:
crossings, point-in-loop, distance, area and the cut-cell quadrature are the spline
loop's, on these spans. Polynomial trims are held exactly; rational ones (circles,
conics) as pieces within a stated tolerance of them (see :mod:`splinedeform.cad_trims`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError
from .bezier import bernstein_to_power
from .spline_loop import SplineLoop


@dataclass(frozen=True)
class PiecewiseLoop(SplineLoop):
    """A closed chain of Bézier pieces; ``control_points`` are the pieces' points
    ``b_{s,a}`` row after row, shape ``(K (n + 1), 2)``, ``degree`` is ``n``.

    Build one with :meth:`from_pieces`; the bounds are those of the Bézier points
    (the convex hull property).
    """

    def __post_init__(self) -> None:
        P = np.asarray(self.control_points, dtype=float)
        n = self.degree
        if n < 1 or P.ndim != 2 or P.shape[1] != 2 or P.shape[0] % (n + 1) or P.shape[0] < 2 * (n + 1):
            raise InputError(f"a loop of degree-{n} Bézier pieces needs (K (n + 1), 2) points, "
                             f"K >= 2, got shape {P.shape}")
        pieces = P.reshape(-1, n + 1, 2)
        gap = np.abs(pieces[:, -1] - np.roll(pieces[:, 0], -1, axis=0)).max()
        if gap > 1e-12 * max(float(np.ptp(P, axis=0).max()), 1e-300):  # round-off of a join
            raise InputError(f"a loop of Bézier pieces must be closed: a piece ends {gap:.3g} "
                             "from where the next begins")
        super().__post_init__()

    @classmethod
    def from_pieces(cls, pieces: NDArray[np.float64]) -> "PiecewiseLoop":
        """The loop of Bézier pieces ``(K, n + 1, 2)``."""
        pieces = np.asarray(pieces, dtype=float)
        if pieces.ndim != 3 or pieces.shape[2] != 2:
            raise InputError(f"Bézier pieces must have shape (K, n + 1, 2), got {pieces.shape}")
        return cls(pieces.reshape(-1, 2), pieces.shape[1] - 1)

    @property
    def pieces(self) -> NDArray[np.float64]:
        """Bézier points ``(K, n + 1, 2)``."""
        return self.control_points.reshape(-1, self.degree + 1, 2)

    @property
    def spans(self) -> int:
        return len(self.control_points) // (self.degree + 1)

    @property
    def power_form(self) -> NDArray[np.float64]:
        """``C[s, e, :] = Σ_a M[e, a] b_{s,a}``, shape ``(K, n+1, 2)``."""
        return np.einsum("ea,sak->sek", bernstein_to_power(self.degree), self.pieces)

    def oriented(self, counter_clockwise: bool) -> "PiecewiseLoop":
        """The same loop, run the other way if needed: pieces in reverse order, each
        reversed (``b_{s,a} → b_{K-1-s, n-a}``)."""
        if (self.signed_area > 0) == counter_clockwise:
            return self
        return PiecewiseLoop.from_pieces(self.pieces[::-1, ::-1].copy())
