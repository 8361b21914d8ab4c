"""Closed-form modal solution of ``q'' + c q' + λ q = g(t)`` (DESIGN.md §1.7).

With ``A = [[0, 1], [-λ, -c]]``, ``a = c/2`` and ``D = a² - λ``, Cayley–Hamilton gives
``(A + aI)² = D I`` and hence the exact propagator

.. math:: e^{Aτ} = e^{-aτ}\\left[C(Dτ²)\\, I + τ\\, S(Dτ²)\\, (A + aI)\\right],

``C(z) = cosh √z``, ``S(z) = sinh √z / √z`` (``cos`` and ``sin``/sinc for ``z < 0``). Both are
entire functions of ``z``, so one formula covers under-, critically and over-damped modes and
``λ = 0`` without cancellation at ``c² = 4λ``; over-damped products ``e^{-aτ}cosh(κτ)`` are
formed as ``(e^{(κ-a)τ} + e^{-(κ+a)τ})/2`` so nothing overflows.

Responses built on it (all exact):

* free response ``[q, q']ᵀ = e^{Aτ} [q_0, v_0]ᵀ``;
* unit step from ``τ = 0``: ``S(τ) = (1 - P_11(τ))/λ``, ``S'(τ) = P_12(τ)``; for ``λ = 0``
  ``S = τ² φ_2(-cτ)``, ``S' = τ φ_1(-cτ)`` with ``φ_1(z) = (e^z-1)/z``, ``φ_2(z) = (e^z-1-z)/z²``;
* ``sin(Ωt + φ)`` from ``t = 0``: particular ``Im(e^{i(Ωt+φ)}/Z)``, ``Z = λ - Ω² + icΩ``, plus the
  free response that cancels its initial values. Near resonance ``1/Z`` is huge and the two
  parts cancel, so under-damped modes with ``ω_d ≥ ω/2`` use instead the Duhamel integral in
  divided-difference form: with ``μ_± = -a ± iω_d``,
  ``q = Im e^{iφ} (E(μ_+) - E(μ_-))/(μ_+ - μ_-)``, ``q' = Im e^{iφ} (μ_+E(μ_+) - μ_-E(μ_-))/(μ_+ - μ_-)``,
  ``E(μ) = ∫_0^t e^{μ(t-s)} e^{iΩs} ds = t e^{μt} φ_1((iΩ-μ)t) = (e^{iΩt} - e^{μt})/(iΩ-μ)``,
  the first form where ``|(iΩ-μ)t| < 1``; nothing cancels for any detuning, resonance included.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

Array = NDArray[np.float64]


def _exp_c_and_s(a: Array, d: Array, tau: Array) -> tuple[Array, Array]:
    """``e^{-aτ} C(Dτ²)`` and ``e^{-aτ} S(Dτ²)`` (see the module docstring), broadcast."""
    a, d, tau = np.broadcast_arrays(a, d, tau)
    ec = np.empty(a.shape)
    es = np.empty(a.shape)
    under = d <= 0
    # under-damped and critical: e^{-aτ} cos(ωτ), e^{-aτ} sin(ωτ)/(ωτ)
    w = np.sqrt(-d[under]) * tau[under]
    e = np.exp(-a[under] * tau[under])
    ec[under] = e * np.cos(w)
    es[under] = e * np.sinc(w / np.pi)
    over = ~under
    x = np.sqrt(d[over]) * tau[over]        # κτ > 0 (or 0 at τ = 0)
    at = a[over] * tau[over]
    small = x < 20.0
    xs, ats = x[small], at[small]
    e = np.exp(-ats)
    ec_o = np.empty(x.shape)
    es_o = np.empty(x.shape)
    ec_o[small] = e * np.cosh(xs)
    es_o[small] = e * np.where(xs > 0, np.sinh(xs) / np.where(xs > 0, xs, 1.0), 1.0)
    xl, atl = x[~small], at[~small]
    plus, minus = np.exp(xl - atl), np.exp(-xl - atl)
    ec_o[~small] = 0.5 * (plus + minus)
    es_o[~small] = 0.5 * (plus - minus) / xl
    ec[over], es[over] = ec_o, es_o
    return ec, es


def propagator(lam: Array, c: Array, tau: Array) -> tuple[Array, Array, Array, Array]:
    """Entries ``P_11, P_12, P_21, P_22`` of ``exp(Aτ)``, ``A = [[0, 1], [-λ, -c]]``.

    Parameters broadcast; ``λ >= 0``, ``c >= 0``, ``τ >= 0``.
    """
    a = 0.5 * np.asarray(c, dtype=float)
    lam = np.asarray(lam, dtype=float)
    tau = np.asarray(tau, dtype=float)
    ec, es = _exp_c_and_s(a, a * a - lam, tau)
    tes = tau * es
    return ec + a * tes, tes, -lam * tes, ec - a * tes


def phi1(z: Array) -> Array:
    """``φ_1(z) = (e^z - 1)/z`` (1 at 0), accurate for all real ``z``."""
    z = np.asarray(z, dtype=float)
    safe = np.where(z == 0, 1.0, z)
    return np.where(z == 0, 1.0, np.expm1(z) / safe)


def phi2(z: Array) -> Array:
    """``φ_2(z) = (e^z - 1 - z)/z²`` (½ at 0); Taylor series for ``|z| < 0.5``."""
    z = np.asarray(z, dtype=float)
    small = np.abs(z) < 0.5
    zs = np.where(small, z, 0.0)
    series = np.zeros_like(z)
    term = np.full_like(z, 0.5)
    for k in range(3, 22):          # Σ z^{k-2}/k!, truncation < 0.5^19/19! ≈ 1e-23
        series += term
        term = term * zs / k
    safe = np.where(small, 1.0, z)
    return np.where(small, series, (np.expm1(safe) - safe) / (safe * safe))


def _phi1_complex(z: NDArray[np.complex128]) -> NDArray[np.complex128]:
    """``φ_1(z) = (e^z - 1)/z`` for complex ``|z| <= 1`` without cancellation.

    ``e^{x+iy} - 1 = expm1(x) cos y - 2 sin²(y/2) + i e^x sin y``.
    """
    x, y = z.real, z.imag
    num = np.expm1(x) * np.cos(y) - 2.0 * np.sin(0.5 * y) ** 2 + 1j * np.exp(x) * np.sin(y)
    zero = z == 0
    return np.where(zero, 1.0 + 0j, num / np.where(zero, 1.0, z))


def _duhamel_exp(mu: NDArray[np.complex128], omega: float, t: Array) -> NDArray[np.complex128]:
    """``E(μ) = ∫_0^t e^{μ(t-s)} e^{iΩs} ds`` (``Re μ <= 0``, ``t >= 0``) without cancellation."""
    w = 1j * omega - mu
    wt = w * t
    small = np.abs(wt) < 1.0
    near = t * np.exp(mu * np.where(small, t, 0.0)) * _phi1_complex(np.where(small, wt, 0.0))
    far = (np.exp(1j * omega * t) - np.exp(mu * t)) / np.where(small, 1.0, w)
    return np.where(small, near, far)


def step_response(lam: Array, c: Array, tau: Array) -> tuple[Array, Array]:
    """Response ``(q, q')`` to a unit force switched on at ``τ = 0`` from rest; 0 for ``τ < 0``."""
    lam, c, tau = np.broadcast_arrays(*(np.asarray(x, dtype=float) for x in (lam, c, tau)))
    on = tau > 0
    tau = np.where(on, tau, 0.0)
    p11, p12, _, _ = propagator(lam, c, tau)
    rigid = lam == 0
    safe = np.where(rigid, 1.0, lam)
    q = np.where(rigid, tau * tau * phi2(-c * tau), (1.0 - p11) / safe)
    v = np.where(rigid, tau * phi1(-c * tau), p12)
    return np.where(on, q, 0.0), np.where(on, v, 0.0)


def harmonic_response(lam: Array, c: Array, omega: float, phase: float, t: Array
                      ) -> tuple[Array, Array]:
    """Response ``(q, q')`` to ``sin(Ω t + φ)`` applied from ``t = 0``, starting at rest."""
    lam, c, t = np.broadcast_arrays(*(np.asarray(x, dtype=float) for x in (lam, c, t)))
    on = t >= 0
    t = np.where(on, t, 0.0)
    z = lam - omega**2 + 1j * c * omega
    resonant = np.abs(z) <= 1e-12 * np.maximum(lam, omega**2)
    zs = np.where(resonant, 1.0, z)
    rot = np.exp(1j * (omega * t + phase))
    rot0 = np.exp(1j * phase)
    qp, vp = np.imag(rot / zs), np.imag(1j * omega * rot / zs)
    qp0, vp0 = np.imag(rot0 / zs), np.imag(1j * omega * rot0 / zs)
    # undamped resonance: q_p = -t cos(Ωt+φ)/(2Ω)
    cos_t, sin_t = np.cos(omega * t + phase), np.sin(omega * t + phase)
    qp = np.where(resonant, -t * cos_t / (2 * omega), qp)
    vp = np.where(resonant, -cos_t / (2 * omega) + 0.5 * t * sin_t, vp)
    qp0 = np.where(resonant, 0.0, qp0)
    vp0 = np.where(resonant, -np.cos(phase) / (2 * omega), vp0)
    p11, p12, p21, p22 = propagator(lam, c, t)
    q = qp - (p11 * qp0 + p12 * vp0)
    v = vp - (p21 * qp0 + p22 * vp0)
    # under-damped with ω_d >= ω/2: divided-difference Duhamel form, exact across resonance
    a = 0.5 * c
    wd2 = lam - a * a
    dd = (lam > 0) & (wd2 >= 0.25 * lam)
    if np.any(dd):
        wd = np.sqrt(np.where(dd, wd2, 1.0))
        mu_p, mu_m = -a + 1j * wd, -a - 1j * wd
        e_p, e_m = _duhamel_exp(mu_p, omega, t), _duhamel_exp(mu_m, omega, t)
        rot0 = np.exp(1j * phase)
        den = 2j * wd
        q = np.where(dd, np.imag(rot0 * (e_p - e_m) / den), q)
        v = np.where(dd, np.imag(rot0 * (mu_p * e_p - mu_m * e_m) / den), v)
    return np.where(on, q, 0.0), np.where(on, v, 0.0)


class ModalResponse:
    """Modal coordinates ``Q(t)``, ``Q'(t)`` of shape ``(F, N, 3)`` at any times, in closed form.

    Parameters
    ----------
    lam, c : ndarray (N,)
        Eigenvalues ``λ_i`` and modal damping. ``λ_i = 0`` exactly marks a rigid-body mode;
        nothing else is snapped to 0 (a soft mode keeps its small ``λ``): the modal basis
        decides the rigid modes from the constraints (:mod:`.rigid`). Round-off negatives
        are clipped to 0.
    q0, v0 : ndarray (N, 3)
        Initial modal displacement and velocity.
    jumps : list of ``(t_j, g_j)``
        The modal force is ``Σ_j g_j H(t - t_j)`` (piecewise constant), ``g_j`` of shape (N, 3).
    harmonics : list of ``(Ω, φ, g)``
        Plus ``Σ g sin(Ωt + φ)`` for ``t >= 0``.
    """

    def __init__(self, lam: Array, c: Array, q0: Array, v0: Array,
                 jumps: list[tuple[float, Array]], harmonics: list[tuple[float, float, Array]]):
        self.lam = np.maximum(np.asarray(lam, dtype=float), 0.0)
        self.c = np.asarray(c, dtype=float)
        merged: dict[float, Array] = {}
        for t_j, g in jumps:
            merged[t_j] = merged.get(t_j, 0.0) + g
        parts = [q0, v0] + [g for g in merged.values()] + [g for _, _, g in harmonics]
        self.width = q0.shape[1]
        self.active = np.flatnonzero(np.any([np.any(p != 0, axis=0) for p in parts], axis=0))
        """Coordinates with a load or an initial condition; the others stay at rest."""
        a = self.active
        self.q0, self.v0 = q0[:, a], v0[:, a]
        self.jumps = sorted((t_j, g[:, a]) for t_j, g in merged.items())
        self.harmonics = [(omega, phase, g[:, a]) for omega, phase, g in harmonics]

    def __call__(self, t: Array) -> tuple[Array, Array]:
        """``Q(t), Q'(t)``, each ``(F, N, 3)`` for times ``t`` of shape ``(F,)``."""
        Q, V = self.active_part(t)
        shape = Q.shape[:2] + (self.width,)
        full_q, full_v = np.zeros(shape), np.zeros(shape)
        full_q[..., self.active], full_v[..., self.active] = Q, V
        return full_q, full_v

    def active_part(self, t: Array) -> tuple[Array, Array]:
        """``Q(t), Q'(t)`` of the :attr:`active` coordinates only, ``(F, N, len(active))``."""
        t = np.asarray(t, dtype=float)[:, None]
        lam, c = self.lam[None, :], self.c[None, :]
        p11, p12, p21, p22 = propagator(lam, c, t)
        Q = p11[..., None] * self.q0 + p12[..., None] * self.v0
        V = p21[..., None] * self.q0 + p22[..., None] * self.v0
        for t_j, g in self.jumps:
            s, ds = step_response(lam, c, t - t_j)
            Q += s[..., None] * g
            V += ds[..., None] * g
        for omega, phase, g in self.harmonics:
            s, ds = harmonic_response(lam, c, omega, phase, t)
            Q += s[..., None] * g
            V += ds[..., None] * g
        return Q, V
