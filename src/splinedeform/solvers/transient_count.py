"""How many modes the transient correction needs, and how many to compute to find them.

The transient correction (:mod:`.transient_correction`) of the modes above ``λ_{m+1}``
has the bound ``Σ_j ‖R_j(m)‖_M E_d(λ_{m+1}, t − t_j)`` (:func:`transient_bound`), at
most the static correction's (``E_d ≤ E``). :func:`transient_count` finds the fewest of
``k + 1`` computed modes that meet a tolerance with it; where none does,
:func:`transient_grown` estimates how many to compute, continuing ``‖R_j‖`` and the
eigenvalue count past ``λ_{k+1}`` by powers of ``λ`` fitted over the upper half of the
computed modes (:func:`norm_power`, :func:`count_power`), and :func:`over_damped_count`
how many reach the first over-damped mode. An estimate too low costs one more round on
the same Krylov space; one too high, modes never used.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from .transient_correction import DEGREE, fitted, over_damped_from

Array = NDArray[np.float64]


def transient_bound(norms: Array, jump_times: Array, lam_next: float, gamma: float,
                    beta: float, times: Array, degree: int = DEGREE) -> Array:
    """``Σ_j ‖R_j‖_M E_d(λ_{m+1}, t − t_j) H(t − t_j)`` for rows of ``norms`` (``(r, J)``)
    at ``times`` → ``(r, T)``: the bound of
    :class:`.transient_correction.TransientCorrection`."""
    tau = times[None, :] - np.asarray(jump_times, dtype=float)[:, None]       # (J, T)
    out = np.zeros((norms.shape[0], times.size))
    on = tau > 0
    if np.any(on):
        E = np.zeros(tau.shape)
        E[on] = fitted(lam_next, gamma, beta, tau[on], degree)[1]
        out += norms @ E
    return out


def count_power(lam: Array, k: int) -> float:
    """The power ``q`` of ``m + 1 ≈ c λ_{m+1}^q`` fitted over ``m ∈ [k/2, k]``, clipped to
    ``[0.3, 1.5]`` (``1`` where too few modes or eigenvalues are equal)."""
    half = np.arange(k // 2, k + 1)
    if half.size <= 2 or not np.ptp(np.log(lam[half])) > 0:
        return 1.0
    return float(np.clip(np.polyfit(np.log(lam[half]), np.log(half + 1.0), 1)[0], 0.3, 1.5))


def norm_power(k: int, lam: Array, norms: Array) -> float:
    """The power (``≤ 0``) of ``Σ_j ‖R_j(m)‖_M ≈ c λ_{m+1}^s`` fitted over ``m ∈ [k/2, k]``."""
    half = np.arange(k // 2, k + 1)
    if half.size <= 2 or not np.ptp(np.log(lam[half])) > 0:
        return 0.0
    total = np.maximum(norms[:, half].sum(axis=0), 1e-300)
    return min(float(np.polyfit(np.log(lam[half]), np.log(total), 1)[0]), 0.0)


def over_damped_count(k: int, lam: Array, gamma: float, beta: float) -> int:
    """The modes to compute so that the first over-damped one (``λ ≥ λ_o``,
    :func:`.transient_correction.over_damped_from`) is among them, from ``k + 1`` computed
    (``k`` where none is over-damped or one is computed already):
    the count below ``λ_o`` continued as the power of :func:`count_power`, plus 10 % and
    8 modes (an estimate too low costs one more round on the same Krylov space)."""
    lam_o = over_damped_from(gamma, beta)
    if lam[k] >= lam_o or not np.isfinite(lam_o):
        return k
    below = (k + 1.0) * (lam_o / lam[k]) ** count_power(lam, k)
    return int(np.ceil(1.1 * below)) + 8


def transient_count(upto: int, lam: Array, norms: Array, jump_times: Array, gamma: float,
                    beta: float, times: Array, weight: float, tolerance: float,
                    static: Array) -> tuple[int, float] | None:
    """Fewer modes than ``upto + 1`` whose bound with the transient correction
    (:func:`transient_bound`) meets ``tolerance`` at ``times``: ``(m, bound)``, or ``None``.

    ``static[m, t]`` is the static correction's relative bound with ``m`` modes at
    ``times[t]``; the transient one is at most that (``E_d ≤ E``,
    :func:`.transient_correction.fitted`), so it is evaluated only at the times where the
    static one misses, and the static one stands for it at the others. Ten counts spaced
    geometrically up to ``upto``, then a bisection between the last that missed and the
    first that met. Every count returned has its bound evaluated (the bound need not fall
    monotonically with ``m``).
    """
    if upto < 1 or not beta > 0:
        return None

    def bound(m: int) -> float:
        missed = static[m] > tolerance
        value = float(static[m][~missed].max(initial=0.0))
        # the time the static bound misses most first: a count that misses there is
        # done with at one time's fit
        order = np.flatnonzero(missed)[np.argsort(-static[m][missed])]
        for chunk in (order[:1], order[1:]):
            if chunk.size:
                value = max(value, float(weight * transient_bound(
                    norms[:, m][None, :], jump_times, float(lam[m]), gamma, beta,
                    times[chunk])[0].max(initial=0.0)))
            if value > tolerance:
                break
        return value

    low = 0
    for m in np.unique(np.geomspace(1, upto, 10).astype(int)):
        value = bound(int(m))
        if value <= tolerance:
            high, best = int(m), value
            break
        low = int(m)
    else:
        return None
    while high - low > 1:
        mid = (low + high) // 2
        value = bound(mid)
        if value <= tolerance:
            high, best = mid, value
        else:
            low = mid
    return high, best


def transient_grown(k: int, lam: Array, norms: Array, jump_times: Array, gamma: float,
                    beta: float, times: Array, weight: float, tolerance: float,
                    static: Array) -> float:
    """The estimate of the modes the transient correction needs, from ``k + 1`` computed
    (``inf`` when no cut-off up to ``max(λ_o, 100 λ_{k+1})`` meets ``tolerance``).

    As in the static estimate (:mod:`.mode_select`), ``‖R_j‖`` is continued past
    ``λ_{k+1}`` as the fitted power of ``λ`` (:func:`norm_power`, never growing) and the
    count below a cut-off ``λ_c`` as that of :func:`count_power`, plus 10 % and 4 modes;
    ``λ_c`` is found by bisection in ``log λ_c`` (to 2 %) on the bound at the times where
    the static one misses (``static``, the static bound at ``k`` per time).
    """
    missed = np.flatnonzero(static > tolerance)
    if not beta > 0 or not missed.size:
        return float(k)
    order = missed[np.argsort(-static[missed])]
    slope, count = norm_power(k, lam, norms), count_power(lam, k)
    lam_o = over_damped_from(gamma, beta)
    top = max(lam_o if np.isfinite(lam_o) else 0.0, 100.0 * lam[k])

    def meets(cut: float) -> bool:
        at = norms[:, k] * min((cut / lam[k]) ** slope, 1.0)
        for chunk in (order[:1], order[1:]):
            if chunk.size and weight * transient_bound(
                    at[None, :], jump_times, cut, gamma, beta,
                    times[chunk])[0].max() > tolerance:
                return False
        return True

    if not meets(top):
        return np.inf
    low, high = np.log(lam[k]), np.log(top)
    while high - low > 0.02:
        mid = 0.5 * (low + high)
        low, high = (low, mid) if meets(float(np.exp(mid))) else (mid, high)
    return 1.1 * (k + 1.0) * (np.exp(high) / lam[k]) ** count + 4.0
