"""The modal state carried from event to event: what the page computes every frame.

Between two events (a push starts, changes or ends) the modal force ``f_i`` is constant and
each mode obeys ``q'' + c q' + λ q = f``. From the state ``(q_0, v_0)`` at the last event,
with ``σ = c/2``, ``s = σ² - λ``, ``a = q_0 - f/λ`` and ``b = v_0``,

    q(τ) = f/λ + e^{-στ} (a C(τ) + (b + σ a) S(τ))
    q'(τ) =      e^{-στ} (b C(τ) - (λ a + σ b) S(τ))

    C(τ) = Σ_n (s τ²)ⁿ/(2n)!  = cos ωτ,        cosh δτ
    S(τ) = τ Σ_n (s τ²)ⁿ/(2n+1)! = sin(ωτ)/ω,  sinh(δτ)/δ      (ω² = -s, δ² = s)

one formula for the under-, critically and over-damped modes: the series is summed when
``|s| τ²`` is small (no ``0/0`` at critical damping) and, over-damped, the products with
``e^{-στ}`` are taken as ``e^{(±δ-σ)τ}`` so nothing overflows. This equals the superposed
step responses of :meth:`SculptBasis.modal` (the state after a step is the step response),
but costs ``O(k)`` per frame however many pushes came before: the page keeps only
``(q, q', f)`` per mode and coordinate. :func:`modal_history` is its Python twin, the one
the tests compare with :meth:`splinedeform.Model.dynamic`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from .modal import Push, SculptBasis

Array = NDArray[np.float64]

SERIES_LIMIT = 1e-3
"""Below this ``|s| τ²`` the series of ``C`` and ``S`` is summed (4 terms: error < 1e-16)."""


def damped_cs(lam: Array, damping: Array, tau: float) -> tuple[Array, Array]:
    """``e^{-στ} C(τ)`` and ``e^{-στ} S(τ)`` of every mode for one ``τ >= 0``."""
    sigma = damping / 2
    s = sigma * sigma - lam
    x = s * tau * tau
    decay = np.exp(-sigma * tau)
    small = np.abs(x) < SERIES_LIMIT
    # series: C = 1 + x/2 + x²/24 + x³/720, S = τ (1 + x/6 + x²/120 + x³/5040)
    c = np.where(small, 1 + x * (1 / 2 + x * (1 / 24 + x / 720)), 0.0)
    sn = np.where(small, tau * (1 + x * (1 / 6 + x * (1 / 120 + x / 5040))), 0.0)
    c, sn = c * decay, sn * decay
    under = ~small & (s < 0)
    omega = np.sqrt(np.where(under, -s, 1.0))
    c = np.where(under, decay * np.cos(omega * tau), c)
    sn = np.where(under, decay * np.sin(omega * tau) / omega, sn)
    over = ~small & (s > 0)
    delta = np.sqrt(np.where(over, s, 1.0))
    grow = np.exp(np.where(over, (delta - sigma) * tau, 0.0))     # e^{(δ-σ)τ} <= 1
    fall = np.exp(np.where(over, (-delta - sigma) * tau, 0.0))
    c = np.where(over, (grow + fall) / 2, c)
    sn = np.where(over, (grow - fall) / (2 * delta), sn)
    return c, sn


def advance(lam: Array, damping: Array, q: Array, v: Array, force: Array, tau: float
            ) -> tuple[Array, Array]:
    """State ``(q, q')`` after ``τ`` under the constant modal force ``force`` (arrays ``(k, 3)``)."""
    c, sn = damped_cs(lam, damping, tau)
    lam_, sigma = lam[:, None], damping[:, None] / 2
    rest = force / lam_
    a = q - rest
    c, sn = c[:, None], sn[:, None]
    return rest + a * c + (v + sigma * a) * sn, v * c - (lam_ * a + sigma * v) * sn


def modal_force(basis: SculptBasis, pushes: Sequence[Push], t: float) -> Array:
    """Modal force ``Σ φ(u, v) P`` of the pushes acting at ``t`` (``t_on <= t < t_off``), ``(k, 3)``."""
    f = np.zeros((basis.lam.size, 3))
    for push in pushes:
        if push.t_on <= t < push.t_off:
            f += basis.participation(push.u, push.v, push.patch)[:, None] * np.asarray(push.force)[None, :]
    return f


def modal_history(basis: SculptBasis, pushes: Sequence[Push], times: Sequence[float]) -> Array:
    """``q(t)`` for ascending ``times`` from rest at ``t = 0``, ``(len(times), k, 3)``.

    The state is advanced from event to event (every ``t_on`` and finite ``t_off``) and
    from there to each requested time, exactly as the page does between frames.
    """
    events = sorted({p.t_on for p in pushes} | {p.t_off for p in pushes if math.isfinite(p.t_off)})
    k = basis.lam.size
    q, v, t0 = np.zeros((k, 3)), np.zeros((k, 3)), 0.0
    force = modal_force(basis, pushes, t0)
    out = np.empty((len(times), k, 3))
    pending = [e for e in events if e > 0.0]
    for n, t in enumerate(times):
        while pending and pending[0] <= t:
            q, v = advance(basis.lam, basis.damping, q, v, force, pending[0] - t0)
            t0 = pending.pop(0)
            force = modal_force(basis, pushes, t0)
        out[n] = advance(basis.lam, basis.damping, q, v, force, t - t0)[0]
    return out
