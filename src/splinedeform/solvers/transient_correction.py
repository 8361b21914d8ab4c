"""The omitted modes' transient, not only their static part: a polynomial in ``K⁻¹M``.

With the lowest ``m`` modes ``Φ`` (``Φᵀ M Φ = I``) and Rayleigh damping ``C = γM + βK``,
every omitted mode ``i`` answers a load jump ``ΔF_j`` at ``t_j`` from rest with
``φ_i (g_ij/λ_i) (1 − P_11(λ_i, τ))``, ``τ = t − t_j``, ``P_11`` the free response from a
unit displacement (:mod:`.mode_count`). Mode acceleration keeps ``φ_i g_ij/λ_i``, whose sum
is ``R_j = K⁻¹ΔF_j − Φ Λ⁻¹ Φᵀ ΔF_j``, and drops ``P_11``. Here ``P_11`` is kept in the form

.. math:: P_{11}(λ, τ) ≈ p_τ(x) = Σ_{k=0}^{d} c_k(τ) T_k(2x − 1),
          \\qquad x = λ_{m+1}/λ ∈ (0, 1],

(``T_k`` Chebyshev polynomials; ``c_k(τ)`` the least-squares fit at Chebyshev points of
``x``), and ``x`` of mode ``i`` is the eigenvalue of ``X = λ_{m+1} K⁻¹M`` on ``φ_i``. ``X``
maps the M-orthogonal complement of ``Φ`` into itself, so

.. math:: u_j(t) = H(τ) \\Big(R_j − Σ_k c_k(τ) T_k(2X − I) R_j\\Big)

is, mode by mode, ``g_ij/λ_i (1 − p_τ(x_i))``: one solve with the factor of ``K`` per
degree and load jump, the vectors kept. Its error is ``Σ_{i>m} φ_i g_ij/λ_i (p_τ − P_11)``,
so, as for the static correction,

.. math:: ‖e(t)‖_M ≤ Σ_j ‖R_j‖_M \\, E_d(λ_{m+1}, τ_j),
          \\qquad E_d = \\sup_{0 < x ≤ 1} |P_{11}(λ_{m+1}/x, τ) − p_τ(x)|,

with ``E_d`` taken on :data:`CHECK` points of ``x`` (uniform and geometric towards 0).
Why it pays: above ``λ = 4/β²`` the modes are over-damped and relax at a rate tending to
``1/β`` whatever ``λ``, so ``P_11`` is a smooth function of ``x`` there (``e^{-τ/β}`` at
``x = 0``) that a low degree follows closely, while the static correction's error stays at
``e^{-τ/β}`` of ``‖R_j‖``: on the bench plate at 24² (a point force), 300 modes and
``τ = t_end/398`` (``8β``), the static correction is 3.1e-10 off in the M-norm, this one
5e-15 (rounding). Below ``λ_o`` the omitted modes still relax at ``a = (γ + βλ)/2``,
fast once ``βλ_{m+1}τ`` is a few units, and ``P_11`` stays smooth enough in ``x`` for a
degree of a dozen or two: on the bench plate (``λ_o ≈ 1.6·10⁷``, the 282nd mode) at
``τ = t_end/398``, ``λ_{m+1} = 3.7·10⁶`` (129 modes) and degree 16, ``E_d = 3.6·10⁻⁸``,
with ``λ_{m+1} = 1.1·10⁶`` (65 modes) degree 32 gives ``3.5·10⁻⁸``. So the fit is made
wherever ``β > 0`` (:func:`fitted`); at each ``τ`` where it does no better, ``c = 0`` and
the bound is the static one.
"""

from __future__ import annotations

import functools
from typing import Callable

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray

from .mode_count import omitted_envelope
from .products import gemm

Array = NDArray[np.float64]
DEGREE = 16
"""Degree of the fit: one solve of the loaded coordinates per degree. On the bench plate
at 128² (default call, 200 frames) degrees 8, 12, 16, 24 kept 154, 135, 115, 85 modes
(281 with degree 8 and over-damped omitted modes only); each degree costs about what a
Lanczos block of 16 solves costs (the factor's memory is read once either way)."""
MARGIN = 1.01
"""Factor on the largest sampled fit error (the supremum between samples)."""
ROUNDING = 1e-15
"""Added to the sampled fit error: the samples' rounding (``‖R_j‖`` relative)."""
FIT = 64
"""Chebyshev points of ``x`` for the fit."""
CHECK = 2000
"""Points of ``x`` on which the fit's error ``E_d`` is taken."""


def free_response(lam: Array, gamma: float, beta: float, tau: Array) -> Array:
    """``P_11(λ, τ)``: ``q'' + c q' + λ q = 0``, ``q(0) = 1``, ``q'(0) = 0``, ``c = γ + βλ``.

    Under-damped ``e^{−aτ}(cos ω_d τ + (a/ω_d) sin ω_d τ)``; over-damped, with the slow
    rate ``r = λ/(a + κ)`` and the fast ``s = a + κ`` (no cancellation for large ``λ``),
    ``(s e^{−rτ} − r e^{−sτ})/(s − r)``; ``a = c/2``, ``κ² = a² − λ = −ω_d²``.
    """
    lam, tau = np.broadcast_arrays(np.asarray(lam, float), np.asarray(tau, float))
    a = 0.5 * (gamma + beta * lam)
    d = a * a - lam
    out = np.ones(lam.shape)
    on = tau > 0
    under, over = on & (d < 0), on & (d >= 0)      # each branch only where it applies
    a_u, t_u = a[under], tau[under]
    wd = np.sqrt(-d[under])
    out[under] = np.exp(-a_u * t_u) * (np.cos(wd * t_u) + a_u / wd * np.sin(wd * t_u))
    out[over] = _over_damped_response(lam[over], a[over], d[over], tau[over])
    return out


def _over_damped_response(lam: Array, a: Array, d: Array, tau: Array) -> Array:
    """``P_11`` of :func:`free_response` where ``d = a² − λ ≥ 0`` (critically or
    over-damped), ``τ > 0``: ``(s e^{−rτ} − r e^{−sτ})/(s − r)``, ``s = a + κ``,
    ``r = λ/s``, ``κ = √d``; ``e^{−aτ}(1 + aτ)`` where ``s = r``."""
    fast = a + np.sqrt(d)
    slow = lam / np.where(fast > 0, fast, 1.0)
    gap = fast - slow
    equal = ~(gap > 0)                      # critically damped: the limit, only there
    out = (fast * np.exp(-slow * tau) - slow * np.exp(-fast * tau)) / np.where(equal, 1.0, gap)
    if equal.any():
        a_e, t_e = a[equal], tau[equal]
        out[equal] = np.exp(-a_e * t_e) * (1.0 + a_e * t_e)
    return out


def _chebyshev(x: Array, degree: int) -> Array:
    """``T_k(2x − 1)`` for ``k = 0..degree``, shape ``(x.size, degree + 1)``."""
    return np.polynomial.chebyshev.chebvander(2.0 * np.asarray(x) - 1.0, degree)


def over_damped_from(gamma: float, beta: float) -> float:
    """The least ``λ_o`` with every ``λ ≥ λ_o`` over-damped, ``(γ + βλ)² ≥ 4λ``
    (the larger root of ``β²λ² + (2γβ − 4)λ + γ² = 0``; ``inf`` without ``β``)."""
    if beta <= 0:
        return np.inf
    b = 4.0 - 2.0 * gamma * beta
    disc = b * b - 4.0 * beta * beta * gamma * gamma
    return 0.0 if disc < 0 or b < 0 else (b + np.sqrt(disc)) / (2.0 * beta * beta)


@functools.lru_cache(maxsize=8)
def _fit_tables(degree: int) -> tuple[Array, Array, Array, Array]:
    """``(nodes, pinv, check, at_check)``: the :data:`FIT` Chebyshev points of ``x``, the
    least-squares map from values there to coefficients, the :data:`CHECK` points and
    ``T_k(2x − 1)`` at them (the same for every cut-off and time; read-only)."""
    nodes = 0.5 * (1.0 - np.cos(np.pi * (np.arange(FIT) + 0.5) / FIT))
    check = np.unique(np.concatenate([np.linspace(0.0, 1.0, CHECK // 2),
                                      np.geomspace(1e-14, 1.0, CHECK // 2)]))
    tables = (nodes, np.linalg.pinv(_chebyshev(nodes, degree)), check,
              _chebyshev(check, degree))
    for table in tables:
        table.flags.writeable = False
    return tables


def fitted(lam_next: float, gamma: float, beta: float, tau: Array, degree: int = DEGREE
           ) -> tuple[Array, Array]:
    """``(c, E)``: the coefficients ``c[k, u]`` of ``p_τ`` at ``tau[u]`` and the bound
    ``E[u]`` (module docstring).

    The fit is made wherever the modes are Rayleigh-damped (``β > 0``), the omitted ones
    under-damped or not: ``P_11`` is an entire function of ``λ`` (``cosh(κτ)`` and
    ``sinh(κτ)/κ`` are entire in ``κ² = a² − λ``), and above ``λ_o``
    (:func:`over_damped_from`) a sum of two decaying exponentials tending to
    ``e^{−τ/β}`` as ``x → 0``, so smooth on ``0 ≤ x ≤ 1``; between ``λ_{m+1}`` and
    ``λ_o`` it oscillates at most at ``ω_d ≤ 1/β``, heavily damped once ``βλτ`` is a
    few units. Its error is sampled on :data:`CHECK` points of ``x`` and taken as
    :data:`MARGIN` times the largest sample plus :data:`ROUNDING` (on the bench plate's
    parameters and others, ``λ_{m+1}`` from 1e2 to 1e9 and ``τ`` from 1e-3 β to 50 β,
    the supremum on 300 000 points exceeded the largest sample by at most 0.3 % where
    it was above 1e-15, ``tests/test_transient_correction.py``). Without ``β``, and at
    each ``τ`` where the fit does no better, ``c = 0`` and ``E`` is the static
    correction's envelope (:func:`.mode_count.omitted_envelope`).
    """
    tau = np.atleast_1d(np.asarray(tau, dtype=float))
    static_error = omitted_envelope(lam_next, gamma, beta, tau)
    c = np.zeros((degree + 1, tau.size))
    if not beta > 0 or not np.isfinite(lam_next):
        return c, static_error
    nodes, pinv, check, at_check = _fit_tables(degree)
    safe = np.where(check > 0, check, 1.0)  # x = 0 is set below

    def response(lam: Array) -> Array:
        return free_response(lam, gamma, beta, tau[None, :])

    fit = pinv @ response(lam_next / nodes[:, None])
    exact = response(lam_next / safe[:, None])
    exact[check == 0] = np.exp(-tau / beta)  # λ → ∞: P_11 → e^{−τ/β}
    fit_error = MARGIN * np.abs(at_check @ fit - exact).max(axis=0) + ROUNDING
    better = fit_error < static_error
    c[:, better] = fit[:, better]
    return c, np.where(better, fit_error, static_error)


class TransientCorrection:
    """``u(t) = Σ_j H(τ_j) (R_j − Σ_k c_k(τ_j) T_k(2X − I) R_j)``, ``X = λ_{m+1} K⁻¹M``.

    Parameters
    ----------
    solve : ``K⁻¹`` (the factor the modes were computed with).
    M : mass matrix; ``phi`` the kept modes (``Φᵀ M Φ = I``), ``lam_next = λ_{m+1}``.
    jump_times, jump_parts : ``t_j`` and ``R_j`` of shape ``(J, n, c)`` (the static
        correction's parts, :class:`~.mode_acceleration.StaticCorrection`).

    Only the coordinates ``c`` in which some ``R_j`` is non-zero (the loaded ones) are
    solved and kept: ``T_k(2X − I)`` maps a zero column to zero.
    """

    def __init__(self, solve: Callable[[Array], Array], M: sp.spmatrix, phi: Array,
                 lam_next: float, gamma: float, beta: float, jump_times: Array,
                 jump_parts: Array, degree: int = DEGREE):
        self.lam_next, self.gamma, self.beta, self.degree = lam_next, gamma, beta, degree
        self.jump_times = np.asarray(jump_times, dtype=float)
        self.jump_parts = np.asarray(jump_parts, dtype=float)
        self.moving = np.flatnonzero(np.any(self.jump_parts != 0, axis=(0, 1)))
        J, n, _ = self.jump_parts.shape
        w = self.moving.size
        R = self.jump_parts[:, :, self.moving].transpose(1, 0, 2).reshape(n, J * w)

        def Z(v: Array) -> Array:               # 2X − I on the complement of Φ
            x = lam_next * np.asarray(solve(M @ v)).reshape(v.shape)
            # rounding and inexact modes stay out
            x = gemm(-1.0, phi, gemm(1.0, phi, np.asarray(M @ x), trans_a=1), 1.0,
                     np.asfortranarray(x))
            return 2.0 * x - v

        terms = [R, Z(R)] if degree >= 1 else [R]
        while len(terms) <= degree:
            terms.append(2.0 * Z(terms[-1]) - terms[-2])
        terms.append(R)                         # R_j itself, weighted by H(τ_j)
        # T_k(2X − I) R_j and R_j as (w, J (d + 2), n): a coordinate's rows contiguous
        self.terms = np.ascontiguousarray(
            np.array(terms).reshape(degree + 2, n, J, w).transpose(3, 2, 0, 1)
        ).reshape(w, J * (degree + 2), n)

    def bound_factor(self, tau: Array) -> Array:
        """``E_d(λ_{m+1}, τ)`` at ``tau`` (``‖e‖_M ≤ Σ_j ‖R_j‖_M E_d(τ_j)``)."""
        return fitted(self.lam_next, self.gamma, self.beta, tau, self.degree)[1]

    def __call__(self, t: Array) -> Array:
        """The correction at times ``t`` (F,) → ``(F, n, c)``."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        out = np.zeros((t.size,) + self.jump_parts.shape[1:])
        self.add_to(t, out)
        return out

    def add_to(self, t: Array, out: Array, columns: Array | None = None) -> None:
        """``out += `` the correction at times ``t`` (``out`` of shape ``(F, n, c)``), in
        place and in the moving coordinates only; ``columns``: the coordinates of ``out``'s
        last axis (default all), which must hold the moving ones.

        Per coordinate one product ``out_c += A B``, ``A = [−c(τ_j)ᵀ, H(τ_j)]_j`` of shape
        ``(F, J (d + 2))`` and ``B`` the rows ``T_k(2X − I) R_j`` and ``R_j``, written into
        ``out`` by ``dgemm`` where its coordinate is Fortran-ordered (a modal expansion of
        one coordinate is)."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        columns = np.arange(out.shape[-1]) if columns is None else np.asarray(columns)
        A = self._weights(t)
        for c, column in enumerate(self.moving):
            where = np.flatnonzero(columns == column)
            if not where.size:
                raise ValueError(f"coordinate {column} moves but is not in the output")
            target = out[:, :, where[0]]
            if target.flags.f_contiguous and target.dtype == np.float64:
                summed = gemm(1.0, A, self.terms[c], 1.0, target)   # in place (Fortran order)
                if not np.shares_memory(summed, target):
                    target[...] = summed
            else:
                target += A @ self.terms[c]

    def coordinate(self, t: Array, p: int, c: int) -> Array:
        """The correction of coordinate ``c`` of unknown ``p`` at times ``t`` → ``(F,)``."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        where = np.flatnonzero(self.moving == c)
        if not where.size:
            return np.zeros(t.size)
        return self._weights(t) @ self.terms[int(where[0]), :, p]

    def _weights(self, t: Array) -> Array:
        """``A`` of :meth:`add_to`: ``A[:, j (d + 2) + k] = −H(τ_j) c_k(τ_j)`` for
        ``k ≤ d`` and ``H(τ_j)`` for ``k = d + 1``, ``τ_j = t − t_j`` (``H(τ) = 0`` for
        ``τ ≤ 0``), shape ``(F, J (d + 2))``."""
        J, d = self.jump_times.size, self.degree
        A = np.zeros((t.size, J, d + 2))
        for j in range(J):                      # a few jumps; vectorised over times
            on = np.flatnonzero(t - self.jump_times[j] > 0)
            if on.size:
                coef, _ = fitted(self.lam_next, self.gamma, self.beta,
                                 t[on] - self.jump_times[j], d)
                A[on, j, :d + 1] = -coef.T
                A[on, j, d + 1] = 1.0
        return A.reshape(t.size, J * (d + 2))
