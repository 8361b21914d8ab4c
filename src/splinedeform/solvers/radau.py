"""Radau IIA collocation for ``M d'' + C d' + K d = F(t)`` with the mass matrix (DESIGN.md §1.8).

The s-stage Radau IIA method (order ``2s - 1``, L-stable, stiffly accurate) applied to the
first-order form ``E y' = J y + g(t)`` with ``y = (d, v)``, ``E = diag(I, M)``,
``J = [[0, I], [-K, -C]]``, ``g = (0, F)``. Its stage increments ``Z_i = Y_i - y₀`` satisfy

    (A⁻¹ ⊗ E) Z - h (I ⊗ J) Z = h (1 ⊗ J y₀ + G),      G_i = g(t₀ + c_i h).

The system is linear, so the stage equations are solved exactly (no Newton iteration) by
diagonalising ``A⁻¹ = T Λ T⁻¹``: with ``W = (T⁻¹ ⊗ I) Z`` each block ``(σ E - h J) W_k = R_k``
reduces to one sparse solve of the displacement part,

    (σ² M + σ h C + h² K) w_d = h R_v + (σ M + h C) R_d,      w_v = (σ w_d - R_d) / h,

one real ``σ`` and ``(s - 1)/2`` complex conjugate pairs (only one of each pair is solved).
The LUs are factorised once per distinct step ``h`` and reused. Since ``c_s = 1``, the new
state is ``y₀ + Z_s``.
"""

from __future__ import annotations

from collections.abc import Callable
from functools import lru_cache
from typing import Any

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from numpy.typing import NDArray

from .._progress import simulated_time
from .stepping import active_columns, left_limit, stops_and_substeps

Array = NDArray[np.float64]


@lru_cache(maxsize=None)
def radau_tableau(stages: int) -> tuple[Array, Array]:
    """Nodes ``c`` and matrix ``A`` of the s-stage Radau IIA method.

    ``c`` are the zeros of ``P_s(2c - 1) - P_{s-1}(2c - 1)`` (so ``c_s = 1``) and
    ``A_ij = ∫₀^{c_i} ℓ_j(τ) dτ`` with ``ℓ_j`` the Lagrange polynomials on ``c``.
    """
    s = int(stages)
    leg = np.polynomial.legendre
    coef = np.zeros(s + 1)
    coef[s], coef[s - 1] = 1.0, -1.0
    x = np.sort(np.real(leg.legroots(coef)))
    x[-1] = 1.0
    c = 0.5 * (x + 1.0)
    # Newton polish of the interior nodes on the Legendre form (keeps c to rounding)
    for _ in range(3):
        val = leg.legval(2 * c[:-1] - 1, coef)
        der = leg.legval(2 * c[:-1] - 1, leg.legder(coef)) * 2
        c[:-1] -= val / der
    powers = np.arange(s)
    vander = c[:, None] ** powers[None, :]
    integral = c[:, None] ** (powers[None, :] + 1) / (powers[None, :] + 1)
    A = np.linalg.solve(vander.T, integral.T).T
    return c, A


@lru_cache(maxsize=None)
def _diagonalisation(stages: int) -> tuple[Array, Array, Array, list[int]]:
    """``A⁻¹ = T Λ T⁻¹``; the indices of one eigenvalue per real value or conjugate pair."""
    _, A = radau_tableau(stages)
    lam, T = np.linalg.eig(np.linalg.inv(A))
    order = np.argsort(lam.imag)
    lam, T = lam[order], T[:, order]
    keep = [k for k in range(stages) if lam[k].imag >= -1e-12 * abs(lam[k])]
    return lam, T, np.linalg.inv(T), keep


def radau(M: sp.spmatrix, C: sp.spmatrix, K: sp.spmatrix, force: Callable[[float], Array],
          breakpoints: list[float], t_end: float, out_times: Array, d0: Array, v0: Array,
          stages: int = 7, dt: float | None = None, substeps: int | None = None
          ) -> tuple[Array, Array, dict[str, Any]]:
    """Integrate with Radau IIA, landing exactly on every breakpoint and output time.

    Each interval between consecutive stops (output times and load breakpoints) is split into
    ``substeps`` equal steps, or into ``ceil(length / dt)`` steps; the default is one step per
    interval. Only the columns of ``d`` that move (non-zero initial state or force at probe
    times) are integrated. The force is sampled at the stage times ``t₀ + c_i h``; at ``c_s = 1``
    the left limit of the interval is used, so a jump at a stop acts from that stop on.

    Returns the displacements and velocities at ``out_times`` (shape ``(len, n, ncoords)``)
    and statistics. The states at the output times carry the method's order ``2s - 1``;
    between output times a :class:`~splinedeform.solution.SampledSolution` interpolates them
    by cubic Hermite polynomials (error ``O(Δt⁴)`` in the frame spacing), not by the
    collocation polynomial.
    """
    stages = int(stages)
    if stages < 1 or stages % 2 == 0:
        raise ValueError(f"Radau IIA stages must be odd and >= 1, got {stages}")
    c, _ = radau_tableau(stages)
    lam, T, Tinv, keep = _diagonalisation(stages)
    stops, counts = stops_and_substeps(breakpoints, t_end, out_times, dt, substeps)
    cols = active_columns(force, breakpoints, t_end, d0, v0)
    M, C, K = (sp.csr_matrix(X) for X in (M, C, K))
    d_out = np.zeros((out_times.size,) + d0.shape)
    v_out = np.zeros((out_times.size,) + d0.shape)
    d, v = d0[:, cols].copy(), v0[:, cols].copy()
    factors: dict[float, list[Any]] = {}
    steps = 0
    k_out = 0
    atol = 1e-12 * t_end
    if out_times[0] <= atol:
        d_out[0][:, cols], v_out[0][:, cols] = d, v
        k_out = 1
    for ta, tb, n_sub in zip(stops[:-1], stops[1:], counts if cols.size else []):
        h = (tb - ta) / n_sub
        key = round(h, 14)
        if key not in factors:
            factors[key] = [spla.splu((lam[k] ** 2 * M + lam[k] * h * C + h * h * K).tocsc())
                            if lam[k].imag else
                            spla.splu((lam[k].real ** 2 * M + lam[k].real * h * C
                                       + h * h * K).tocsc())
                            for k in keep]
        lus = factors[key]
        for j in range(n_sub):
            t0 = ta + j * h
            tails = [min(t0 + ci * h, left_limit(ta, tb)) for ci in c]
            g = np.stack([force(t)[:, cols] for t in tails])            # (s, n, m)
            jd, jv = v, -(K @ d) - (C @ v)                               # J y₀
            rd = h * np.einsum("ki,nm->knm", Tinv, jd)                   # R_k, displacement
            rv = h * (np.einsum("ki,nm->knm", Tinv, jv) + np.einsum("ki,inm->knm", Tinv, g))
            zd = np.zeros_like(d)
            zv = np.zeros_like(v)
            for lu, k in zip(lus, keep):
                sigma = lam[k]
                if sigma.imag:
                    rhs = h * rv[k] + sigma * (M @ rd[k]) + h * (C @ rd[k])
                    wd = lu.solve(rhs.astype(complex))
                    wv = (sigma * wd - rd[k]) / h
                    zd += 2 * np.real(T[-1, k] * wd)
                    zv += 2 * np.real(T[-1, k] * wv)
                else:
                    s_re = sigma.real
                    rhs = np.real(h * rv[k] + s_re * (M @ rd[k]) + h * (C @ rd[k]))
                    wd = lu.solve(rhs)
                    wv = (s_re * wd - np.real(rd[k])) / h
                    zd += np.real(T[-1, k]) * wd
                    zv += np.real(T[-1, k]) * wv
            d, v = d + zd, v + zv
        steps += n_sub
        simulated_time(tb, t_end)
        while k_out < out_times.size and abs(out_times[k_out] - tb) <= atol:
            d_out[k_out][:, cols], v_out[k_out][:, cols] = d, v
            k_out += 1
    stats = {"steps": steps, "factorisations": len(factors) * len(keep), "stages": stages,
             "columns": int(len(cols))}
    return d_out, v_out, stats
