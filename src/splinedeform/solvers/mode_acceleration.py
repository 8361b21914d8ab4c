"""Mode acceleration: the modes left out of a truncated basis respond quasi-statically.

A truncated basis ``Φ`` (the lowest modes) carries ``Φ Q(t)``; the rest of the response is
taken as static, ``R = K⁻¹F − Φ Λ⁻¹ Φᵀ F`` per load term, exact in the static limit. How
large the neglected dynamic part can be is bounded in :mod:`.mode_count`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray

if TYPE_CHECKING:
    from .bases import ModalBasis

Array = NDArray[np.float64]


@dataclass
class StaticCorrection:
    """Mode acceleration: the omitted modes respond quasi-statically.

    For the piecewise-constant load ``F(t) = Σ_j ΔF_j H(t - t_j)`` and harmonic terms
    ``F_h sin(Ωt + φ)`` the truncated solution ``Φ Q(t)`` gets
    ``Σ_j H(t - t_j) R_j + Σ_h sin(Ωt + φ) R_h`` with ``R = K⁻¹F - Φ Λ⁻¹ Φᵀ F``, exact in the
    static limit. ``H(0) = 0``, as in the modal step response.
    """

    jump_times: Array
    jump_parts: Array          # (J, n_free, 3)
    harmonics: list[tuple[float, float, Array]]

    def __call__(self, t: Array) -> Array:
        """Correction at times ``t`` (F,) → ``(F, n_free, 3)``."""
        t = np.asarray(t, dtype=float)
        on = (t[:, None] > self.jump_times[None, :]).astype(float)
        J, n, c = self.jump_parts.shape
        out = (on @ self.jump_parts.reshape(J, n * c)).reshape(t.size, n, c)
        for omega, phase, part in self.harmonics:
            out += np.where(t >= 0, np.sin(omega * t + phase), 0.0)[:, None, None] * part
        return out

    def add_to(self, t: Array, out: Array) -> None:
        """``out += `` the correction at times ``t`` (``out`` of shape ``(F, n_free, 3)``),
        in place; of the jumps only the coordinates some ``R_j`` moves are touched."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        on = (t[:, None] > self.jump_times[None, :]).astype(float)
        for c in np.flatnonzero(np.any(self.jump_parts != 0, axis=(0, 1))):
            out[:, :, c] += on @ self.jump_parts[:, :, c]
        for omega, phase, part in self.harmonics:
            out += np.where(t >= 0, np.sin(omega * t + phase), 0.0)[:, None, None] * part

    def coordinate(self, t: Array, p: int, c: int) -> Array:
        """The correction of coordinate ``c`` of unknown ``p`` at times ``t`` → ``(F,)``."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        out = (t[:, None] > self.jump_times[None, :]).astype(float) @ self.jump_parts[:, p, c]
        for omega, phase, part in self.harmonics:
            out += np.where(t >= 0, np.sin(omega * t + phase), 0.0) * part[p, c]
        return out


def mode_acceleration(basis: ModalBasis, K: sp.spmatrix, M: sp.spmatrix,
                      jumps: list[tuple[float, Array]],
                      harmonics: list[tuple[float, float, Array]]
                      ) -> tuple[StaticCorrection, dict[str, float]]:
    """The static correction of a truncated basis and its error indicators.

    Returns the correction and

    * ``omitted_static = max_j ‖R_j‖_M / ‖K⁻¹F_j‖_M``: for a piecewise-constant load each
      omitted mode's exact response is ``g_i/λ_i (1 - P_11(τ))`` against ``g_i/λ_i`` here,
      so the error in the M-norm is at most ``max|P_11| · Σ_j ‖R_j‖_M`` with
      ``|P_11| <= 1/√(1-ζ²)`` (``<= 1`` for over-damped modes); this is its relative size;
    * ``static_residual = max_j ‖K K⁻¹F_j - F_j‖ / ‖F_j‖``: the static limit is exact to it.
    """
    merged: dict[float, Array] = {}
    for t_j, F in jumps:
        merged[t_j] = merged.get(t_j, 0.0) + F
    times = np.array(sorted(merged), dtype=float)
    loads = [merged[float(t_j)] for t_j in times] + [F for _, _, F in harmonics]
    parts, omitted, residual = [], [0.0], [0.0]
    for F in loads:
        full = basis.static(F)
        part = full - basis.modal_static(F)
        parts.append(part)
        omitted.append(_m_norm(M, part) / max(_m_norm(M, full), 1e-300))
        residual.append(float(np.linalg.norm(K @ full - F) / max(np.linalg.norm(F), 1e-300)))
    columns = parts[0].shape[-1] if parts else 3          # 3 coordinates, or 1 (the shell)
    jump_parts = (np.array(parts[:times.size]) if times.size
                  else np.zeros((0, basis.n_free, columns)))
    harmonic_parts = [(omega, phase, part) for (omega, phase, _), part
                      in zip(harmonics, parts[times.size:])]
    return (StaticCorrection(times, jump_parts, harmonic_parts),
            {"omitted_static": float(max(omitted)), "static_residual": float(max(residual))})


def _m_norm(M: sp.spmatrix, x: Array) -> float:
    return float(np.sqrt(max(np.sum(x * (M @ x)), 0.0)))
