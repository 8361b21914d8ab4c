"""Generalised-α (Chung & Hulbert 1993) for ``M d'' + C d' + K d = F(t``) (DESIGN.md §1.8).

With spectral radius at infinity ``ρ∞``: ``α_m = (2ρ∞ - 1)/(ρ∞ + 1)``, ``α_f = ρ∞/(ρ∞ + 1)``,
``β = (1 - α_m + α_f)²/4``, ``γ = ½ - α_m + α_f`` (second order, unconditionally stable).
Each step solves the balance at ``t_{n+1-α_f}``

    M a_{n+1-α_m} + C v_{n+1-α_f} + K d_{n+1-α_f} = F(t_{n+1-α_f}),
    d₊ = d + h v + h² ((½ - β) a + β a₊),   v₊ = v + h ((1 - γ) a + γ a₊),

for ``a₊`` with ``[(1 - α_m) M + (1 - α_f) γ h C + (1 - α_f) β h² K]``, one LU per step size.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from numpy.typing import NDArray

from .._progress import simulated_time
from .stepping import active_columns, stops_and_substeps

Array = NDArray[np.float64]


def genalpha(M: sp.spmatrix, C: sp.spmatrix, K: sp.spmatrix, force: Callable[[float], Array],
             breakpoints: list[float], t_end: float, out_times: Array, d0: Array, v0: Array,
             rho_inf: float = 0.9, dt: float | None = None, substeps: int | None = None
             ) -> tuple[Array, Array, dict[str, Any]]:
    """Integrate with generalised-α, landing exactly on every breakpoint and output time.

    The step count is free: each interval between stops is split into ``substeps`` equal
    steps or ``ceil(length / dt)`` (default ``t_end / 2000``). The acceleration restarts
    from the right limit of the force at every stop. Only the moving columns are integrated.
    States at the output times are second-order accurate; between them a
    :class:`~splinedeform.solution.SampledSolution` interpolates by cubic Hermite polynomials.
    """
    rho = float(rho_inf)
    if not 0.0 <= rho <= 1.0:
        raise ValueError(f"rho_inf must lie in [0, 1], got {rho_inf}")
    if dt is None and substeps is None:
        dt = t_end / 2000
    am, af = (2 * rho - 1) / (rho + 1), rho / (rho + 1)
    beta, gamma = 0.25 * (1 - am + af) ** 2, 0.5 - am + af
    stops, counts = stops_and_substeps(breakpoints, t_end, out_times, dt, substeps)
    cols = active_columns(force, breakpoints, t_end, d0, v0)
    M, C, K = (sp.csr_matrix(X) for X in (M, C, K))
    mass_lu = spla.splu(M.tocsc())
    d_out = np.zeros((out_times.size,) + d0.shape)
    v_out = np.zeros((out_times.size,) + d0.shape)
    d, v = d0[:, cols].copy(), v0[:, cols].copy()
    factors: dict[float, Any] = {}
    steps, k_out, atol = 0, 0, 1e-12 * t_end
    if out_times[0] <= atol:
        d_out[0][:, cols], v_out[0][:, cols] = d, v
        k_out = 1
    for ta, tb, n_sub in zip(stops[:-1], stops[1:], counts if cols.size else []):
        h = (tb - ta) / n_sub
        key = round(h, 14)
        if key not in factors:
            factors[key] = spla.splu(((1 - am) * M + (1 - af) * gamma * h * C
                                      + (1 - af) * beta * h * h * K).tocsc())
        lu = factors[key]
        a = mass_lu.solve(force(ta)[:, cols] - C @ v - K @ d)
        for j in range(n_sub):
            t_mid = ta + (j + 1 - af) * h
            d_pred = d + h * v + h * h * (0.5 - beta) * a
            v_pred = v + h * (1 - gamma) * a
            rhs = (force(t_mid)[:, cols] - am * (M @ a)
                   - C @ ((1 - af) * v_pred + af * v) - K @ ((1 - af) * d_pred + af * d))
            a1 = lu.solve(rhs)
            d, v, a = d_pred + beta * h * h * a1, v_pred + gamma * h * a1, a1
        steps += n_sub
        simulated_time(tb, t_end)
        while k_out < out_times.size and abs(out_times[k_out] - tb) <= atol:
            d_out[k_out][:, cols], v_out[k_out][:, cols] = d, v
            k_out += 1
    return d_out, v_out, {"steps": steps, "factorisations": len(factors) + 1,
                          "columns": int(len(cols))}
