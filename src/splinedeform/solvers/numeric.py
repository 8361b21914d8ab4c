"""Numerical reference integrators for ``M p'' + C p' + K p = F(t)`` (DESIGN.md §1.8).

* Newmark-β, average acceleration (β = ¼, γ = ½): unconditionally stable, second order;
  ``K_eff = K + (2/Δt) C + (4/Δt²) M`` factorised once per distinct step.
* ``scipy.integrate.solve_ivp`` (RK45, DOP853, Radau, BDF) on the first-order form
  ``y = (d, v)``, ``v' = M⁻¹ (F - C v - K d)`` with a sparse LU of ``M``; the stiff methods get
  the exact (dense) Jacobian. This is what a casual user does; the strong integrators are
  :mod:`.radau` (Radau IIA with the mass matrix) and :mod:`.genalpha`.
* ``radau3``/``radau5``/``radau7`` and ``genalpha`` take the matrices directly
  (:func:`.radau.radau`, :func:`.genalpha.genalpha`).

All restart at the load's breakpoints (steps and switches), so discontinuities do not cost
accuracy. :func:`run` takes the reduced matrices, the forcing and the output times and
returns the states at those times; the model wraps them in a
:class:`~splinedeform.solution.SampledSolution`.
"""

from __future__ import annotations

from typing import Any, Callable

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from numpy.typing import ArrayLike, NDArray
from scipy.integrate import solve_ivp

from .._progress import simulated_time
from ..errors import InputError
from .forcing import ReducedForcing  # noqa: F401 (public here too)
from .genalpha import genalpha
from .radau import radau
from .stepping import active_columns

Array = NDArray[np.float64]
IVP_METHODS = {"rk45": "RK45", "dop853": "DOP853", "radau": "Radau", "bdf": "BDF"}
RADAU_METHODS = {"radau3": 3, "radau5": 5, "radau7": 7}
ONE_STEP_METHODS = (*RADAU_METHODS, "genalpha")


def _output_times(times: ArrayLike | None, t_end: float) -> Array:
    if times is None:
        return np.linspace(0.0, t_end, 201)
    out = np.asarray(times, dtype=float).ravel()
    if out.size == 0 or not np.all(np.isfinite(out)):
        raise InputError("output times must be a non-empty array of finite numbers")
    if np.any(np.diff(out) <= 0) or out[0] < 0 or out[-1] > t_end:
        raise InputError(f"output times must increase within [0, t_end={t_end:g}]")
    return out


def _segments(breakpoints: list[float], t_end: float) -> list[tuple[float, float]]:
    cuts = sorted({0.0, t_end, *[b for b in breakpoints if 0.0 < b < t_end]})
    return list(zip(cuts[:-1], cuts[1:]))


def _left_limit(a: float, b: float) -> float:
    return b - 1e-12 * (b - a)


def run(M: sp.spmatrix, C: sp.spmatrix, K: sp.spmatrix, forcing: Callable[[float], Array],
        breakpoints: list[float], method: str, t_end: float, times: ArrayLike | None,
        d0: Array, v0: Array, **options: Any) -> tuple[Array, Array, Array, dict]:
    """Integrate ``M d'' + C d' + K d = F(t)`` with ``method`` to the output ``times``.

    Returns ``(times, d, v, stats)`` with ``d``, ``v`` of shape ``(F, n, 3)`` at the checked
    output times (default 201 evenly spaced on ``[0, t_end]``).
    """
    out_times = _output_times(times, t_end)
    if method == "newmark":
        d, v, stats = newmark(M, C, K, forcing, breakpoints, t_end, out_times, d0, v0,
                              **options)
    elif method in ONE_STEP_METHODS:
        try:
            if method == "genalpha":
                d, v, stats = genalpha(M, C, K, forcing, breakpoints, t_end, out_times,
                                       d0, v0, **options)
            else:
                d, v, stats = radau(M, C, K, forcing, breakpoints, t_end, out_times,
                                    d0, v0, stages=RADAU_METHODS[method], **options)
        except (TypeError, ValueError) as exc:
            raise InputError(f"method {method!r}: {exc}") from None
    else:
        d, v, stats = ivp(M, C, K, forcing, breakpoints, IVP_METHODS[method], t_end,
                          out_times, d0, v0, **options)
    return out_times, d, v, stats


def newmark(M: sp.spmatrix, C: sp.spmatrix, K: sp.spmatrix, forcing: Callable[[float], Array],
            breakpoints: list[float], t_end: float, out_times: Array, d0: Array, v0: Array,
            dt: float | None = None) -> tuple[Array, Array, dict]:
    """Average-acceleration Newmark with steps of at most ``dt`` hitting every output time.

    Update: ``K_eff d₊ = F₊ + M (4/Δt² d + 4/Δt v + a) + C (2/Δt d + v)``, then
    ``a₊ = 4/Δt² (d₊ - d) - 4/Δt v - a`` and ``v₊ = v + Δt/2 (a + a₊)``.
    """
    if dt is None:
        dt = t_end / 2000
    dt = float(dt)
    if not np.isfinite(dt) or dt <= 0:
        raise InputError(f"Newmark step dt must be finite and > 0, got {dt}")
    mass_lu = spla.splu(M)
    factors: dict[float, Any] = {}
    stops = np.union1d(out_times, [t for seg in _segments(breakpoints, t_end) for t in seg])
    stops = stops[np.concatenate([[True], np.diff(stops) > 1e-9 * t_end])]   # merge near-equal
    d, v = d0.copy(), v0.copy()
    acc = lambda t, d, v: mass_lu.solve(forcing(t) - C @ v - K @ d)  # noqa: E731
    a = acc(0.0, d, v)
    d_out, v_out = np.empty((out_times.size,) + d0.shape), np.empty((out_times.size,) + d0.shape)
    steps = 0
    k_out = 0
    if out_times[0] == 0.0:
        d_out[0], v_out[0], k_out = d, v, 1
    for ta, tb in zip(stops[:-1], stops[1:]):
        n_sub = max(1, int(np.ceil((tb - ta) / dt - 1e-9)))
        h = (tb - ta) / n_sub
        key = round(h, 15)
        if key not in factors:
            factors[key] = spla.splu((K + (2 / h) * C + (4 / h**2) * M).tocsc())
        lu = factors[key]
        a = acc(ta, d, v)                       # restart with the right-hand limit of F
        for j in range(1, n_sub + 1):
            t1 = ta + j * h
            F1 = forcing(_left_limit(ta, tb) if j == n_sub else t1)
            rhs = F1 + M @ ((4 / h**2) * d + (4 / h) * v + a) + C @ ((2 / h) * d + v)
            d1 = lu.solve(rhs)
            a1 = (4 / h**2) * (d1 - d) - (4 / h) * v - a
            v = v + 0.5 * h * (a + a1)
            d, a = d1, a1
        steps += n_sub
        simulated_time(tb, t_end)
        while k_out < out_times.size and np.isclose(out_times[k_out], tb, rtol=0, atol=1e-12 * t_end):
            d_out[k_out], v_out[k_out] = d, v
            k_out += 1
    return d_out, v_out, {"steps": steps, "factorisations": len(factors)}


def ivp(M: sp.spmatrix, C: sp.spmatrix, K: sp.spmatrix, forcing: Callable[[float], Array],
        breakpoints: list[float], method: str, t_end: float, out_times: Array,
        d0: Array, v0: Array, rtol: float = 1e-8, atol: float = 1e-12,
        max_step: float = np.inf) -> tuple[Array, Array, dict]:
    """``solve_ivp`` on ``y = (d_c, v_c)`` for the moving coordinates ``c``, restarted at
    breakpoints; the other coordinates stay at rest."""
    for name, value in (("rtol", rtol), ("atol", atol)):
        if not np.isfinite(value) or value <= 0:
            raise InputError(f"{name} must be finite and > 0, got {value}")
    n = M.shape[0]
    mass_lu = spla.splu(M)
    cols = active_columns(forcing, breakpoints, t_end, d0, v0)
    m = len(cols)

    def rhs(t: float, y: Array) -> Array:
        simulated_time(t, t_end)
        state = y.reshape(m, 2, n)
        d, v = state[:, 0].T, state[:, 1].T
        a = mass_lu.solve(forcing(t)[:, cols] - C @ v - K @ d)
        return np.stack([v.T, a.T], axis=1).ravel()

    options: dict[str, Any] = {"rtol": rtol, "atol": atol, "max_step": max_step}
    if method in ("Radau", "BDF") and m:
        options["jac"] = _jacobian(M, C, K, m)
    y = np.stack([d0[:, cols].T, v0[:, cols].T], axis=1).ravel()
    d_out, v_out = np.zeros((out_times.size, n, 3)), np.zeros((out_times.size, n, 3))
    stats = {"nfev": 0, "njev": 0, "nlu": 0, "columns": m}
    filled = 0
    for ta, tb in _segments(breakpoints, t_end):
        last = tb == t_end
        inside = out_times[(out_times >= ta) & ((out_times <= tb) if last else (out_times < tb))]
        if not m:
            filled += inside.size
            continue
        seg_rhs = lambda t, y, ta=ta, tb=tb: rhs(min(t, _left_limit(ta, tb)), y)  # noqa: E731
        sol = solve_ivp(seg_rhs, (ta, tb), y, method=method,
                        t_eval=np.union1d(inside, [tb]), **options)
        if not sol.success:
            raise InputError(f"{method} failed: {sol.message}")
        for key in ("nfev", "njev", "nlu"):
            stats[key] += int(getattr(sol, key))
        states = sol.y[:, : inside.size].T.reshape(-1, m, 2, n)
        d_out[filled:filled + inside.size][:, :, cols] = states[:, :, 0].transpose(0, 2, 1)
        v_out[filled:filled + inside.size][:, :, cols] = states[:, :, 1].transpose(0, 2, 1)
        filled += inside.size
        y = sol.y[:, -1]
        simulated_time(tb, t_end)
    return d_out, v_out, stats


def _jacobian(M: sp.spmatrix, C: sp.spmatrix, K: sp.spmatrix, columns: int) -> Array:
    """Exact Jacobian ``[[0, I], [-M⁻¹K, -M⁻¹C]]`` per moving coordinate, as a dense array.

    ``M⁻¹`` of a B-spline mass matrix is dense, so the exact Jacobian of the first-order form
    is dense; given as an ndarray, ``solve_ivp`` factorises ``I - h γ J`` with LAPACK rather
    than a sparse LU of a dense matrix. ``M⁻¹K`` and ``M⁻¹C`` come from one Cholesky of ``M``.
    """
    n = M.shape[0]
    factor = sla.cho_factor(M.toarray())
    block = np.zeros((2 * n, 2 * n))
    block[:n, n:] = np.eye(n)
    block[n:, :n] = -sla.cho_solve(factor, K.toarray())
    block[n:, n:] = -sla.cho_solve(factor, C.toarray())
    return sla.block_diag(*[block] * columns) if columns > 1 else block
