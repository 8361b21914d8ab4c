"""How many modes a requested accuracy needs: an a-priori bound on the omitted modes.

With the lowest ``k`` modes and the exact static part of the rest (mode acceleration), a
piecewise-constant load ``F(t) = Σ_j ΔF_j H(t - t_j)`` from rest leaves the error

.. math:: e(t) = -Σ_j H(t - t_j) Σ_{i > k} φ_i \\frac{g_{ij}}{λ_i} P_{11}(λ_i, τ_j),
          \\quad τ_j = t - t_j,

(each omitted mode's step response is ``g/λ (1 - P_11)``, the correction ``g/λ``). Since
``Σ_{i>k} (g_ij/λ_i)² = ‖R_j‖²_M`` with ``R_j = K⁻¹ΔF_j − Φ Λ⁻¹ Φᵀ ΔF_j`` (the static part the
correction adds, computed exactly),

.. math:: ‖e(t)‖_M ≤ Σ_j ‖R_j‖_M \\, E(t - t_j),
          \\quad E(τ) = \\sup_{λ ≥ λ_{k+1}} |P_{11}(λ, c(λ), τ)|,

with ``c(λ) = γ/μ + βλ``. ``|P_11|`` is the free response from a unit displacement, so it is
at most 1 (its energy decays) and, with ``a = c/2``:

* under-damped (``ω_d² = λ − a² > 0``): ``|P_11| ≤ e^{−aτ}(1 + a·min(τ, 1/ω_d))``;
* critically or over-damped (``κ = √(a² − λ)``, slow rate ``r = a − κ = λ/(a + κ)``):
  ``P_11 ≤ e^{−rτ} min((a + κ)/(2κ), 1 + aτ)``.

``E`` is the largest of these on a grid of :data:`GRID` values of ``λ`` over
:data:`DECADES` decades from ``λ_{k+1}`` (the bounds vary smoothly in ``log λ``). The number
of modes must make ``max_t Σ_j ‖R_j‖_M E(t − t_j) ≤ tol · max_t ‖K⁻¹F(t)‖_M`` at the
requested times: what it costs is set by the load's jumps and the damping, not by the net.
The fewest modes meeting it are chosen in :mod:`.mode_select`, which also states it for
the largest control-point coordinate (``c_∞ Σ_j ‖R_j‖_M E(t − t_j) ≤ tol · max_t
‖K⁻¹F(t)‖_∞``, ``c_∞ ≥ max_p √((M⁻¹)_pp)``).

Each bound above is non-increasing in ``τ`` (the under-damped one has derivative
``−a²τ e^{−aτ}`` before ``1/ω_d``; ``(1 + aτ)e^{−rτ}`` rises above 1 and falls back, so
capped at 1 it never rises), hence so is ``E``: the bound at a time also holds at every
later time up to the next jump, and only the time just after a jump (``E → 1``) is not
covered by the bound at an earlier one.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

Array = NDArray[np.float64]
GRID = 3000
DECADES = 12.0


def decay_bound(lam: Array, c: Array, tau: Array) -> Array:
    """Upper bound of ``|P_11(λ, c, τ)|`` (see the module docstring), broadcast.

    Both branches are one form, ``min(1, e^{−sτ} min(A, 1 + a·min(τ, τ₀)))``: under-damped
    ``s = a``, ``A = ∞``, ``τ₀ = 1/ω_d``; over-damped ``s = r``, ``A = (a + κ)/(2κ)``,
    ``τ₀ = ∞``. ``s``, ``A`` and ``τ₀`` depend on ``(λ, c)`` only and are formed on their
    broadcast shape; the ``τ`` axis costs one exponential per entry.
    """
    lam, c = np.broadcast_arrays(np.asarray(lam, dtype=float), np.asarray(c, dtype=float))
    tau = np.asarray(tau, dtype=float)
    a = 0.5 * c
    d = a * a - lam
    under = d < 0
    wd = np.sqrt(np.where(under, -d, 1.0))
    kappa = np.sqrt(np.where(under, 0.0, d))
    rate = lam / np.where(a + kappa > 0, a + kappa, 1.0)     # used where over-damped
    ratio = np.where(kappa > 0, (a + kappa) / (2.0 * np.where(kappa > 0, kappa, 1.0)), np.inf)
    s = np.where(under, a, rate)
    cap = np.where(under, np.inf, ratio)
    until = np.where(under, 1.0 / wd, np.inf)
    later = np.maximum(tau, 0.0)                            # τ ≤ 0 reads 1 below
    out = np.exp(-s * later) * np.minimum(cap, 1.0 + a * np.minimum(later, until))
    return np.where(tau > 0, np.minimum(out, 1.0), 1.0)


def omitted_envelope(lam_first: float, gamma: float, beta: float, tau: Array) -> Array:
    """``E(τ) = sup_{λ ≥ λ_first} |P_11|`` for modal damping ``c = γ + βλ``, on a log grid."""
    tau = np.asarray(tau, dtype=float)
    if not np.isfinite(lam_first):
        return np.zeros_like(tau)
    grid = lam_first * np.logspace(0.0, DECADES, GRID)
    return decay_bound(grid[:, None], gamma + beta * grid[:, None], tau[None, :]).max(axis=0)


def error_bound(norms: Array, jump_times: Array, lam_first: float, gamma: float, beta: float,
                times: Array) -> Array:
    """``Σ_j ‖R_j‖_M E(t − t_j) H(t − t_j)`` at ``times`` (``norms[j] = ‖R_j‖_M``)."""
    times = np.asarray(times, dtype=float)
    out = np.zeros(times.shape)
    for t_j, r in zip(jump_times, norms):
        tau = times - t_j
        on = tau > 0
        if r > 0 and np.any(on):
            out[on] += r * omitted_envelope(lam_first, gamma, beta, tau[on])
    return out
