"""The fewest modes meeting a requested accuracy, from one sparse LU of ``K``.

The bound is that of :mod:`.mode_count`: with the lowest ``m`` modes and the exact static
part of the rest, a piecewise-constant load from rest is in error by at most

.. math:: ‖e(t)‖_M ≤ Σ_j ‖R_j(m)‖_M \\, E(λ_{m+1}, t − t_j),
          \\qquad E(λ_f, τ) = \\sup_{λ ≥ λ_f} |P_{11}(λ, c(λ), τ)|.

What makes choosing ``m`` cheap:

* **one factorisation** of ``K`` (:func:`.sparse_eigen.factorise`) serves the eigen-solution
  (:func:`.sparse_eigen.lowest_modes`), the static solves ``K⁻¹ΔF_j`` of the bound and the
  static part of the omitted modes in the solution; only the coordinates that are loaded
  are solved;
* **a space started from the load** (``load_started``, a few times asked): the Krylov
  space of ``K⁻¹M`` from ``K⁻¹ΔF`` holds only the modes the load excites, one vector per
  load direction per block, so its lowest pairs converge in about half the solves of a
  random start; it serves that load alone;
* **every m at once**: from ``k + 1`` computed modes, one explicit ``R_j(k)`` and the modal
  static coefficients ``g_ij/λ_i`` give ``‖R_j(m)‖²_M = ‖R_j(k)‖²_M + Σ_{m<i≤k} (g_ij/λ_i)²``
  for all ``m ≤ k`` (sums of squares, nothing cancels);
* **one table of E**: :func:`.mode_count.decay_bound` on a log grid of ``λ`` (from ``λ_1``
  over :data:`DECADES` decades, :data:`GRID` points, as :func:`.mode_count.omitted_envelope`)
  at the distinct ``τ = t − t_j > 0``, with a running maximum from the top of the grid: row
  ``i`` is the supremum over grid values ``≥ λ_i``. A cut-off between grid points reads the
  row below it, the supremum over a larger set, so the bound is never lowered.

So ``m`` is the smallest count whose bound meets the tolerance at the requested ``times``
(one state: the fewest modes that time allows), relative to ``max_t ‖K⁻¹F(t)‖_M`` or, with
``pointwise = c_∞``, as ``c_∞ × bound`` relative to ``max_t ‖K⁻¹F(t)‖_∞`` — the largest
control-point coordinate, since ``|x_p| ≤ c_∞ ‖x‖_M`` (:func:`pointwise_bound`). When even all ``k`` computed modes miss it,
``k`` grows to an estimate of the count needed (:func:`_grown`) and the same Krylov space
is extended: the LU and every solve so far are kept. An estimate of ``n/2`` modes or more
made from at least 64 computed ends the search: all modes are cheaper then (a frame a few
milliseconds after a jump of the bench plate needs them, as its over-damped modes relax
no faster than ``1/β``) — unless the transient correction (:mod:`.transient_correction`,
bound ``Σ_j ‖R_j‖_M E_d``) meets the tolerance with fewer modes than the static one: then
it is taken (:func:`.transient_count.transient_count`, evaluated only at the times where
the static bound misses). With Rayleigh damping the correction follows the omitted modes'
relaxation, under-damped ones included, so the search grows to the count it estimates
(:func:`.transient_count.transient_grown`) or, at most, to the first over-damped mode
(:func:`.transient_count.over_damped_count`): on the bench plate at 128² and the
default call's times, 135 modes from 17, 65 and 154 computed (464 Krylov vectors), where
the static estimate's growth computed 627 (1 376 vectors) to keep 281. From 16
modes the estimate is not trusted: a uniform load's ``‖R‖``, flat over the symmetric
modes it does not excite, predicted 2 400 where 33 did.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray

from .bases import DenseBasis
from .mode_acceleration import StaticCorrection
from .modal_basis import DEFAULT_ADVICE
from .products import selected_rows
from .mode_count import decay_bound, error_bound
from .rigid import check_resolved
from .sparse_eigen import BlockLanczos, factorise
from .transient_correction import DEGREE, TransientCorrection, over_damped_from
from .transient_count import (count_power, norm_power, over_damped_count, transient_bound,
                              transient_count, transient_grown)

Array = NDArray[np.float64]
GRID = 3500
DECADES = 14.0
START = 16
"""Modes computed first; the selection may keep fewer."""
FEW_TIMES = 16
"""Up to this many times, a count that meets the tolerance with the static correction is
kept without looking for fewer modes with the transient one."""
NEAR = 8
"""At up to :data:`FEW_TIMES` times, a static estimate (:func:`_grown`) within this many
modes of those computed is grown to without trying the transient correction: its
:data:`~.transient_correction.DEGREE` solves per load jump and its fit cost about what
five to ten more modes of a one-vector Krylov space cost (about three solves a mode: 60
for 20 at 64²)."""
LOAD_STARTED_MODES = 48
"""A space started from the load serves up to this many modes (its blocks are one vector
per load direction); a search for more goes on in a random-start space."""


@dataclass(frozen=True)
class ErrorEstimate:
    """The a-priori bound of a chosen basis at any time:
    ``relative(t) = weight · Σ_j ‖R_j‖_M E(λ_{m+1}, t − t_j)``.

    ``weight`` is ``c_∞ / max_t ‖K⁻¹F(t)‖_∞`` (max norm, :func:`pointwise_bound`) or
    ``1 / max_t ‖K⁻¹F(t)‖_M``. The static ``E`` is non-increasing in ``τ`` (each of its
    bounds is), so the value at a time also bounds every later time up to the next jump;
    the transient ``E_d`` (``degree > 0``) need not be, and is evaluated at each time asked.
    """

    jump_times: Array
    norms: Array               # ‖R_j(m)‖_M, (J,)
    lam_next: float            # λ_{m+1}
    gamma: float
    beta: float
    weight: float
    degree: int = 0            # > 0: the transient correction's E_d (.transient_correction)

    def relative(self, times: Array) -> Array:
        """The bound at ``times`` (relative, in the measure the basis was chosen in)."""
        times = np.asarray(times, dtype=float)
        if not self.degree:
            return self.weight * error_bound(self.norms, self.jump_times, self.lam_next,
                                             self.gamma, self.beta, times)
        return self.weight * transient_bound(self.norms[None, :], self.jump_times,
                                             self.lam_next, self.gamma, self.beta, times,
                                             self.degree)[0]


def pointwise_bound(M: sp.spmatrix, T: sp.spmatrix | None = None,
                    inverse_diagonal: Array | None = None) -> float:
    """``c_∞`` with ``|x_p| ≤ c_∞ ‖x‖_M`` for every coordinate ``p`` of every ``x``.

    ``|x_p| = |(M⁻¹e_p)ᵀ M x| ≤ √((M⁻¹)_pp) ‖x‖_M`` (Cauchy–Schwarz in the M inner product),
    so ``c_∞ = max_p √((M⁻¹)_pp)``. ``inverse_diagonal``: the diagonal of the *unreduced*
    mass matrix's inverse, valid when ``T`` only selects coordinates (``M_r`` is then a
    principal submatrix and ``(M_r⁻¹)_pp ≤ (M⁻¹)_pp``, the Schur complement). Otherwise a
    diagonal ``M`` gives ``1/M_pp`` and a general one ``1/λ_min(M)`` (``(M⁻¹)_pp ≤
    λ_max(M⁻¹)``), ``λ_min`` from Lanczos less its residual norm (a lower bound).
    """
    rows = None if inverse_diagonal is None or T is None else selected_rows(T)
    if rows is not None:
        return float(np.sqrt(np.max(inverse_diagonal[rows])))
    diagonal = M.diagonal()
    if sp.issparse(M) and M.nnz == np.count_nonzero(diagonal):
        return float(np.sqrt(np.max(1.0 / diagonal)))
    import scipy.sparse.linalg as spla
    n = M.shape[0]
    if n <= 400:
        low = float(np.linalg.eigvalsh(M.toarray() if sp.issparse(M) else M)[0])
    else:
        value, vector = spla.eigsh(M, k=1, which="SA", tol=1e-8)
        residual = float(np.linalg.norm(M @ vector[:, 0] - value[0] * vector[:, 0]))
        low = float(value[0]) - residual
    return float(np.sqrt(1.0 / max(low, 1e-300)))


def envelope_table(lam_low: float, gamma: float, beta: float, tau: Array
                   ) -> tuple[Array, Array]:
    """``(grid, E)``: ``E[i, u] = max_{g ≥ i} |P_11|``-bound at ``grid[g]``, ``tau[u]``."""
    grid = lam_low * np.logspace(0.0, DECADES, GRID)
    values = decay_bound(grid[:, None], gamma + beta * grid[:, None], tau[None, :])
    return grid, np.maximum.accumulate(values[::-1], axis=0)[::-1]


def _grown(k: int, lam: Array, norms: Array, grid: Array, E: Array, column: Array,
           limit: float) -> tuple[int, float]:
    """The next number of modes to compute when ``k`` miss the bound, and the estimate of
    the number needed (``inf`` when no cut-off on the grid meets ``limit``).

    ``‖R(m)‖ = Σ_j ‖R_j(m)‖_M`` is continued past ``λ_{k+1}`` as the power of ``λ_{m+1}``
    fitted over ``m ∈ [k/2, k]`` (never growing); the cut-off ``λ_c`` is the lowest grid
    value where that times ``E`` meets ``limit`` at every requested time, and the count of
    eigenvalues below it is continued as the power of ``λ`` fitted over the same modes
    (a membrane's count grows like ``λ``, a plate's like ``√λ``), plus 10 %, between
    ``1.25 k`` and ``4 k``. An estimate too low costs one more round on the same Krylov
    space; one too high, modes never used.
    """
    slope, count = norm_power(k, lam, norms), count_power(lam, k)
    decay = np.minimum((grid / lam[k]) ** slope, 1.0)
    at_grid = np.zeros((grid.size, column.shape[0]))
    for j in range(norms.shape[0]):
        at_grid += norms[j, k] * E[:, column[:, j]]
    ok = np.flatnonzero((at_grid.max(axis=1) * decay <= limit) & (grid >= lam[k]))
    grow = np.inf if not ok.size else 1.1 * (grid[ok[0]] / lam[k]) ** count
    return int(np.ceil(min(max(grow, 1.25), 4.0) * k)), grow * k


def _m_norm2(mass: Callable[[Array], Array], x: Array) -> float:
    """``Σ_c x_cᵀ M x_c`` for ``x`` of shape ``(n, c)``; ``mass``: ``X ↦ M X``."""
    return float(max(np.sum(x * mass(x)), 0.0))


def automatic_basis(K: sp.spmatrix, M: sp.spmatrix, jumps: list[tuple[float, Array]],
                    gamma: float, beta: float, times: Array, tolerance: float,
                    start: int = START, advice: str = "", krylov: BlockLanczos | None = None,
                    pointwise: float | None = None, best_effort: bool = False,
                    load_started: bool = False, mass_product: Any | None = None
                    ) -> tuple[Any, Any, dict[str, Any]]:
    """The fewest lowest modes whose a-priori bound (module docstring) meets ``tolerance``
    at ``times``: relative to ``max_t ‖K⁻¹F(t)‖_M`` in the M-norm, or, with ``pointwise``,
    in the largest control-point coordinate (:func:`pointwise_bound`).

    Parameters
    ----------
    K, M : reduced stiffness (positive definite) and mass.
    jumps : ``(t_j, ΔF_j)`` with ``ΔF_j`` of shape ``(n, 3)``: ``F(t) = Σ_j ΔF_j H(t − t_j)``.
    gamma, beta : modal damping ``c(λ) = γ + βλ``.
    times : the times at which the accuracy is wanted.
    krylov : the Krylov space (and its LU of ``K``) of an earlier call on the same ``K``
        and ``M``, extended if more modes are needed; a further load case then costs its
        static solves and the bound, not a new eigen-solution.
    load_started : with no ``krylov``, start the space from the load's static responses
        ``K⁻¹ΔF_j`` (:class:`~.sparse_eigen.BlockLanczos` ``start``) instead of a random
        block: only the modes the load excites are computed (half the solves at 64² for the
        bench plate's point force), and the space serves this load alone (returned as
        ``report["krylov"]`` with ``report["load_started"]``; its modes must not serve
        another load); with ``krylov``: that space was started so (from this load).
    best_effort : where all modes would be needed, return the computed ones instead (their
        bound, above ``tolerance``, in the report with ``met = False``): for nets whose
        complete eigen-solution is out of reach.
    mass_product : ``X ↦ M X`` for the Krylov space (:class:`~.sparse_eigen.BlockLanczos`).
    pointwise : ``c_∞ ≥ max_p √((M⁻¹)_pp)``: the bound becomes
        ``c_∞ Σ_j ‖R_j‖_M E(t − t_j) / max_t ‖K⁻¹F(t)‖_∞`` (:func:`pointwise_bound`).

    Returns
    -------
    basis, correction, report
        A truncated :class:`~.modal_basis.DenseBasis` (its static solve is the LU), the
        :class:`~.mode_acceleration.StaticCorrection` (or the
        :class:`~.transient_correction.TransientCorrection`, ``correction_degree`` > 0 in
        the report) and a report (``modes``, ``bound``,
        ``tolerance``, ``omitted_static``, ``static_residual``, ``computed``: modes found,
        ``solves``). ``(None, None, report)`` when ``n/2`` modes or more would be needed:
        all modes are cheaper then.
    """
    n = K.shape[0]
    merged: dict[float, Array] = {}
    for t_j, F in jumps:
        merged[t_j] = merged.get(t_j, 0.0) + np.asarray(F, dtype=float)
    jump_times = np.array(sorted(merged), dtype=float)
    width = 3 if not merged else next(iter(merged.values())).shape[1]
    loads = (np.array([merged[float(t)] for t in jump_times]) if merged
             else np.zeros((0, n, width)))
    active = np.flatnonzero(np.any(loads != 0, axis=(0, 1)))
    F = loads[:, :, active]                                   # (J, n, a)
    J, a = F.shape[0], active.size
    report: dict[str, Any] = {"tolerance": tolerance}
    mass = mass_product or M.__matmul__
    lu = factorise(K) if krylov is None else krylov.lu
    flat = np.ascontiguousarray(F.transpose(1, 0, 2)).reshape(n, J * a)
    solved = np.asarray(lu.solve(flat)) if J * a else np.zeros((n, 0))
    statics = solved.reshape(n, J, a).transpose(1, 0, 2)
    if krylov is None:
        load_started = bool(load_started and np.any(solved))
        krylov = BlockLanczos(K, M, lu, start=solved if load_started else None,
                              mass_product=mass_product)
    report.update(krylov=krylov, load_started=load_started)
    if pointwise is None:
        scale = np.sqrt(max((_m_norm2(mass, s) for s in np.cumsum(statics, axis=0)),
                            default=0.0))
        factor = 1.0
    else:
        scale, factor = float(np.abs(np.cumsum(statics, axis=0)).max(initial=0.0)), pointwise
    times = np.asarray(times, dtype=float)
    tau_all = times[:, None] - jump_times[None, :]
    tau, where = np.unique(np.where(tau_all > 0, tau_all, np.inf), return_inverse=True)
    where = where.reshape(tau_all.shape)
    top = float(np.max(K.diagonal() / M.diagonal()))
    k = min(start, n // 2)
    table: tuple[Array, Array] | None = None
    last: tuple | None = None
    while 1 <= k < n // 2:
        if load_started and k > LOAD_STARTED_MODES:
            # many modes: narrow blocks orthogonalise slowly, and a load exciting few modes
            # fills its invariant subspace; the model's random-start space, same LU
            krylov, load_started = BlockLanczos(K, M, lu, mass_product=mass_product), False
            report.update(krylov=krylov, load_started=False)
        modes = krylov.lowest(k)
        lam = check_resolved(modes.lam, 0, "sparse eigen-solution",
                             advice or DEFAULT_ADVICE, top)
        k = lam.size - 1
        if table is None:
            grid, E = envelope_table(float(lam[0]), gamma, beta, tau[np.isfinite(tau)])
            E = np.hstack([E, np.zeros((E.shape[0], 1))])      # τ ≤ 0: no contribution
            table = (grid, E)
        grid, E = table
        coef = np.array([modes.project(f) for f in F]) / lam[None, :, None]  # g_ij/λ_i
        rest = statics - np.array([modes.combine(c[:k]) for c in coef])
        r2 = np.array([_m_norm2(mass, r) for r in rest])                     # ‖R_j(k)‖²
        tail = np.sum(coef[:, :k] ** 2, axis=2)                           # (J, k)
        later = np.cumsum(tail[:, ::-1], axis=1)[:, ::-1]                  # Σ_{i ≥ m}
        norms = np.sqrt(r2[:, None] + np.hstack([later, np.zeros((J, 1))]))  # m = 0..k
        rows = np.searchsorted(grid, lam, side="right") - 1                # λ_{m+1} = lam[m]
        column = where                      # (T, J) into E; τ ≤ 0 reads the zero column
        bound = np.zeros((k + 1, times.size))
        for j in range(J):
            bound += norms[j, :, None] * E[rows][:, column[:, j]]
        relative = factor * bound.max(axis=1, initial=0.0) / max(scale, 1e-300)
        fits = np.flatnonzero(relative[1:] <= tolerance) + 1
        report.update(computed=k, solves=modes.solves)
        last = (k, modes, lam, coef, norms, relative)
        weight = factor / max(scale, 1e-300)
        # where the static bound meets the tolerance at a few times, fewer modes with the
        # transient correction would save little of their evaluation and cost its solves;
        # so would it where the static one is expected to with a few more modes (NEAR)
        estimate = None if fits.size or times.size > FEW_TIMES else _grown(
            k, lam, norms, grid, E, column, tolerance * scale / factor)
        near = estimate is not None and estimate[1] <= k + NEAR
        dynamic = None if (fits.size and times.size <= FEW_TIMES) or near else transient_count(
            int(fits[0]) - 1 if fits.size else k, lam, norms, jump_times, gamma, beta, times,
            weight, tolerance, weight * bound)
        if fits.size or dynamic is not None:
            m, bound_m = dynamic if dynamic is not None else (int(fits[0]), relative[fits[0]])
            parts = statics - np.array([modes.combine(c[:m]) for c in coef])
            jump_parts = np.zeros((J, n, width))
            jump_parts[:, :, active] = parts
            basis = DenseBasis(lam[:m], modes.columns(m), "sparse", False, lu.solve,
                               float(lam[m]))
            omitted = [np.sqrt(_m_norm2(mass, p) / max(_m_norm2(mass, s), 1e-300))
                       for p, s in zip(parts, statics)]
            residual = [np.linalg.norm(K @ s - f) / max(np.linalg.norm(f), 1e-300)
                        for s, f in zip(statics, F)]
            degree = DEGREE if dynamic is not None else 0
            report.update(modes=m, bound=float(bound_m), scale=float(scale),
                          omitted_static=float(max(omitted, default=0.0)),
                          static_residual=float(max(residual, default=0.0)),
                          correction_degree=degree,
                          estimate=ErrorEstimate(jump_times, norms[:, m], float(lam[m]),
                                                 gamma, beta, weight, degree))
            if dynamic is not None:
                correction: Any = TransientCorrection(lu.solve, M, basis.phi, float(lam[m]),
                                                      gamma, beta, jump_times, jump_parts)
            else:
                correction = StaticCorrection(jump_times, jump_parts, [])
            return basis, correction, report
        grown, needed = estimate or _grown(k, lam, norms, grid, E, column,
                                           tolerance * scale / factor)
        if near and load_started:
            # the space serves this call alone and grows a vector at a time: ask for the
            # count estimated (one more round if it is short) rather than 1.25 k
            grown = max(k + 1, int(np.ceil(needed)))
        if k >= 64 and lam[k] < over_damped_from(gamma, beta):
            # the transient correction applies from the first over-damped mode on: grow to
            # it where the static correction is expected to need more modes (or half)
            over = max(over_damped_count(k, lam, gamma, beta), int(1.25 * k))
            if over < needed or needed >= n // 2:
                grown, needed = over, over
        elif k >= 64 and np.isfinite(needed) and needed >= n // 2:
            break                   # half the modes or more: all of them are cheaper
        if k >= 64 and beta > 0:    # and below λ_o with the under-damped modes' transient
            estimate = transient_grown(k, lam, norms, jump_times, gamma, beta, times, weight,
                                        tolerance, weight * bound[k])
            if estimate < needed:
                grown = max(int(np.ceil(estimate)), int(1.25 * k))
        k = min(grown, n // 2 - 1) if grown < n // 2 or k < n // 2 - 1 else grown
    if best_effort and last is not None:
        m, modes, lam, coef, norms, relative = last       # every mode computed, bound missed
        parts = statics - np.array([modes.combine(c[:m]) for c in coef])
        jump_parts = np.zeros((J, n, width))
        jump_parts[:, :, active] = parts
        basis = DenseBasis(lam[:m], modes.columns(m), "sparse", False, lu.solve, float(lam[m]))
        report.update(modes=m, bound=float(relative[m]), scale=float(scale), met=False,
                      estimate=ErrorEstimate(jump_times, norms[:, m], float(lam[m]), gamma,
                                             beta, factor / max(scale, 1e-300)))
        return basis, StaticCorrection(jump_times, jump_parts, []), report
    report.update(modes=n, bound=0.0)
    return None, None, report
