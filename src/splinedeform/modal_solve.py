"""The analytic path of :meth:`splinedeform.Model.dynamic`: modes, modal forces, response.

``d(t) = Φ Q(t)`` with the closed-form modal coordinates of
:class:`~splinedeform.solvers.analytic.ModalResponse`; a truncated basis (``modes``,
``omega_max`` or ``tolerance``) adds the exact static part of the omitted modes
(:mod:`~splinedeform.solvers.mode_acceleration`) and reports the truncation.
"""

from __future__ import annotations

import time
import warnings
import weakref
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
import scipy.sparse as sp
from numpy.typing import ArrayLike, NDArray

from . import spectrum
from .errors import InputError
from .modal_solution import ModalSolution
from .solvers import modal_basis, mode_select
from .solvers.sparse_eigen import BlockLanczos
from .solvers.analytic import ModalResponse
from .solvers.rigid import UnresolvedSpectrum

if TYPE_CHECKING:
    from .model import Model

Array = NDArray[np.float64]
_KRYLOV: weakref.WeakKeyDictionary[Any, BlockLanczos] = weakref.WeakKeyDictionary()
"""Per model: the Krylov space and LU of the automatic mode count, kept for further load
cases (a model's ``K`` and ``M`` never change; the space lives as long as the model)."""
#: up to this many free coordinates the automatic mode count takes all modes at once: the
#: dense eigen-solution costs no more than the sparse one (one BLAS thread, the bench
#: plate at 1e-8, load average 4: 32², 961 free, 1.7 s all modes against 1.6 s for 201
#: sparse modes; 24², 529 free, 0.18 s against 0.77 s; at 64² 35 s against 5 s)
DENSE_BELOW = 1024
DEFAULT_TOLERANCE = 1e-8
"""The accuracy :meth:`splinedeform.Model.dynamic` keeps by default: largest control-point
coordinate error at most this fraction of the largest static displacement, at any time."""
DEFAULT_TIMES = 201
"""Without ``times=`` the modes are chosen for this many evenly spaced times on ``[0, t_end]``
and, after each load jump, the time half their spacing later (:func:`default_times`)."""
_POINTWISE: weakref.WeakKeyDictionary[Any, float] = weakref.WeakKeyDictionary()
ONE_OFF_TIMES = 16
"""Up to this many times given at the call, on a model with no Krylov space yet, the modes
are computed from a space started from the load (:func:`_automatic_modes`)."""


def analytic(model: Model, forcing: Any, t_end: float, d0: Array, v0: Array,
             function_samples: int = 400, modes: int | str | None = None,
             omega_max: float | None = None, eigensolver: str = "auto",
             tolerance: float | None = None, times: ArrayLike | None = None,
             check_spectrum: bool = True, _of_static: bool = False) -> ModalSolution:
    """Closed-form modal solution; ``modes``/``omega_max`` truncate with mode acceleration,
    ``tolerance`` chooses the number of modes (:mod:`~splinedeform.solvers.mode_count`).

    With none of ``modes``, ``omega_max`` and ``tolerance`` the modes are chosen for
    :data:`DEFAULT_TOLERANCE` where the bound applies (piecewise-constant loads from rest,
    no rigid modes) and all modes are taken otherwise; ``modes="all"`` takes all modes.
    """
    requested = tolerance
    if isinstance(modes, str):
        if modes != "all":
            raise InputError(f"modes must be an integer >= 1 or 'all', got {modes!r}")
        if tolerance is not None or omega_max is not None:
            raise InputError("modes='all' takes every mode: give it without tolerance= or "
                             "omega_max=")
        modes = None
    elif modes is None and omega_max is None and tolerance is None:
        tolerance = DEFAULT_TOLERANCE
    modes, omega_max = truncation_request(model, modes, omega_max)
    # the reduced force terms in space: modal terms of the identity basis
    spatial = forcing.modal_terms(sp.identity(model.n_free, format="csr"), t_end,
                                  function_samples)
    report: dict[str, Any] = {}
    if requested is not None:
        report = _automatic_modes(model, spatial, d0, v0, t_end, tolerance, times,
                                  modes, omega_max, _of_static)
    elif tolerance is not None and _bound_applies(model, spatial, d0, v0, eigensolver):
        try:
            report = _automatic_modes(model, spatial, d0, v0, t_end, tolerance, times,
                                      modes, omega_max)
        except UnresolvedSpectrum:
            report = {}                  # all modes: the auto eigen-solution resolves them
    if report and report["modes"] < model.n_free:
        modes, eigensolver = report["modes"], "sparse"
    basis = report.pop("basis", None)
    if basis is None:
        basis = model.modal_basis(eigensolver, modes, omega_max, check_spectrum)
    start = time.perf_counter()
    M, _, K = model.matrices()
    lam = basis.lam
    c = model.formulation.damping_rate + model.formulation.rayleigh * lam
    jumps = [(t_j, basis.project(F)) for t_j, F in spatial[0]]
    harmonics = [(w, phase, basis.project(F)) for w, phase, F in spatial[1]]
    def initial(x: Array) -> Array:
        """``Φᵀ M x`` (no products for a start from rest)."""
        x = np.asarray(x, dtype=float)
        return basis.project(M @ x) if np.any(x) else np.zeros((lam.size,) + x.shape[1:])

    response = ModalResponse(lam, c, initial(d0), initial(v0), jumps, harmonics)
    correction, truncation = report.pop("correction", None), {}
    estimate, chosen_at = report.pop("estimate", None), report.pop("times", None)
    if not basis.complete:
        correction, truncation = _truncation(model, basis, spatial, d0, v0, correction)
    if report:
        truncation.update({key: report[key] for key in ("tolerance", "bound", "omitted_static",
                                                        "static_residual", "met",
                                                        "correction_degree")
                           if key in report})
    timings = dict(model.timings)
    timings["modal setup"] = time.perf_counter() - start
    accuracy = None
    if estimate is not None and not basis.complete:
        of_static = float(report["of_static"])
        accuracy = Accuracy(of_static, estimate, chosen_at,
                            lambda at: analytic(model, forcing, t_end, d0, v0,
                                                function_samples, tolerance=of_static,
                                                times=at, _of_static=True))
    return ModalSolution(model.readout, t_end, forcing, timings, basis, response, truncation,
                         correction, accuracy)


@dataclass
class Accuracy:
    """What keeps a solution of the automatic mode count within ``tolerance`` at any time.

    ``estimate`` bounds the error of the solution's basis at any ``t``; when it exceeds
    ``tolerance`` at a time asked (only just after a load jump: the bound is
    non-increasing between jumps), ``refine(times)`` gives a solution whose modes are chosen
    for ``times``, which serves such times from then on. ``chosen_at``: the times the basis
    was chosen for (the bound holds there).
    """

    tolerance: float
    estimate: mode_select.ErrorEstimate
    chosen_at: Array
    refine: Callable[[Array], ModalSolution]

    def outside(self, times: Array) -> Array:
        """Mask of the ``times`` at which the basis' bound exceeds the tolerance."""
        times = np.asarray(times, dtype=float)
        ask = ~np.isin(times, self.chosen_at)
        out = np.zeros(times.shape, dtype=bool)
        if np.any(ask):
            out[ask] = self.estimate.relative(times[ask]) > self.tolerance
        return out


def _bound_applies(model: Model, spatial: tuple[list, list], d0: Array, v0: Array,
                   eigensolver: str) -> bool:
    """Whether the default call counts its modes: the bound covers the problem
    (piecewise-constant load from rest, no rigid modes), no eigensolver was asked for, and
    all modes are not cheaper (more than :data:`DENSE_BELOW` free coordinates, no
    separable factors, which give all modes in ``O(n^{3/2})``)."""
    return bool(eigensolver == "auto" and not spatial[1] and not np.any(d0)
                and not np.any(v0) and model.n_free > DENSE_BELOW
                and model.rigid_modes == 0 and spectrum.separable_reason(model) is not None)


def _automatic_modes(model: Model, spatial: tuple[list, list], d0: Array, v0: Array,
                     t_end: float, tolerance: Any, times: ArrayLike | None,
                     modes: int | None, omega_max: float | None, of_static: bool = False
                     ) -> dict[str, Any]:
    """Lowest modes meeting ``tolerance`` at ``times``: the largest control-point coordinate
    error relative to the largest displacement on ``[0, t_end]`` (``of_static``: to the
    largest static displacement ``S``). The report of
    :func:`~splinedeform.solvers.mode_select.automatic_basis` (``modes = n_free``: all),
    with its static correction under ``"correction"``, its error estimate under
    ``"estimate"`` and the tolerance relative to ``S`` it met under ``"of_static"``; all
    modes, exact, on nets of at most :data:`DENSE_BELOW` free coordinates.

    The bound is relative to ``S``. When the motion stays below it (a short horizon),
    ``D = max_t |d_p(t)| − bound(t)·S`` at the coordinate ``p`` of ``S``, on the
    :data:`DEFAULT_TIMES` grid and ``times``, is a lower bound of the largest displacement,
    and the modes are chosen again for ``tolerance · D / S``.
    """
    try:
        tolerance = float(tolerance)
    except (TypeError, ValueError):
        raise InputError(f"tolerance must be a number, got {tolerance!r}") from None
    if not 0 < tolerance < 1:
        raise InputError(f"tolerance must be in (0, 1), got {tolerance}")
    if modes is not None or omega_max is not None:
        raise InputError("give tolerance= or modes=/omega_max=, not both")
    if spatial[1] or np.any(d0) or np.any(v0) or model.rigid_modes != 0:
        raise InputError("tolerance= chooses the modes for piecewise-constant loads from "
                         "rest on a model without rigid modes; give modes=k otherwise")
    if model.n_free <= DENSE_BELOW:
        return {"tolerance": tolerance, "modes": model.n_free, "bound": 0.0}
    at = (default_times(t_end, [t_j for t_j, _ in spatial[0]]) if times is None
          else np.asarray(times, dtype=float).ravel())
    physics = model.formulation
    M, _, K = model.matrices()
    krylov = _KRYLOV.get(model)
    # a few times asked at the call on a model with no space yet: a space started from the
    # load (fewer solves), for this call alone; else the model's random-start space, kept
    # for further load cases
    one_off = krylov is None and times is not None and at.size <= ONE_OFF_TIMES
    mass_product = spectrum.kronecker_mass(model, M)
    if krylov is None and not one_off:
        krylov = _KRYLOV[model] = BlockLanczos(K, M, mass_product=mass_product)
    gamma, beta, c_inf = physics.damping_rate, physics.rayleigh, pointwise_factor(model)
    out_of_reach = model.n_free > modal_basis.DENSE_MAX    # all modes cannot be had
    basis, correction, report = mode_select.automatic_basis(
        K, M, spatial[0], gamma, beta, at, tolerance, krylov=krylov, pointwise=c_inf,
        best_effort=out_of_reach, load_started=one_off, mass_product=mass_product)
    krylov = report.pop("krylov")
    if one_off and not report.get("load_started"):
        _KRYLOV[model] = krylov               # the search went on in a random-start space
        one_off = False
    report["of_static"] = tolerance
    if basis is not None and not of_static:
        grid = np.union1d(np.linspace(0.0, t_end, DEFAULT_TIMES), at)
        largest = _largest_below(basis, correction, report, spatial[0], gamma, beta, grid)
        if largest < report["scale"]:
            below = tolerance * max(largest, 0.0) / report["scale"]
            basis, correction, report = (None, None, {"tolerance": tolerance}) if below <= 0 \
                else mode_select.automatic_basis(K, M, spatial[0], gamma, beta, at, below,
                                                 krylov=krylov, pointwise=c_inf,
                                                 best_effort=out_of_reach,
                                                 load_started=one_off,
                                                 mass_product=mass_product)
            report.update(tolerance=tolerance, of_static=below)
            if one_off and not report.get("load_started", True):
                _KRYLOV[model] = report["krylov"]       # went on in a random-start space
            report.pop("krylov", None)
            if basis is not None:
                report["bound"] *= tolerance / below
    if report.get("met") is False:
        warnings.warn(
            f"the tolerance {tolerance:g} is not met at every time asked: all "
            f"{model.n_free} modes would be needed (times just after a load jump), more than "
            f"a dense eigen-solution takes ({modal_basis.DENSE_MAX}); {report['modes']} modes "
            f"reach a bound of {report['bound']:.2g} (solution.truncation['bound']). Ask "
            "times further after the jumps, a looser tolerance=, or fewer cells",
            stacklevel=4)
    if basis is None:
        report["modes"] = model.n_free
    else:
        if report.pop("load_started", False):
            report["basis"] = basis          # the load's modes only: not the model's
        else:
            model._bases[("sparse", report["modes"], None)] = basis
        report["correction"] = correction
        report["times"] = at
    return report


def default_times(t_end: float, jump_times: list[float]) -> Array:
    """The times the default call chooses its modes for: :data:`DEFAULT_TIMES` evenly
    spaced on ``[0, t_end]`` and ``t_j + Δ/2`` after each jump ``t_j`` (``Δ`` their
    spacing, within ``[0, t_end]``). Just after a jump the bound falls steeply with
    ``t − t_j``; frames closer to a jump than the grid's first time after it (any other
    even grid of as many frames) would otherwise need a second basis chosen for them
    (:class:`Accuracy`), its Krylov space shared but its correction solved again."""
    grid = np.linspace(0.0, t_end, DEFAULT_TIMES)
    half = 0.5 * t_end / (DEFAULT_TIMES - 1)
    after = np.asarray(jump_times, dtype=float) + half
    return np.union1d(grid, after[(after >= 0.0) & (after <= t_end)])


def _largest_below(basis: Any, correction: Any, report: dict[str, Any], jumps: list,
                   gamma: float, beta: float, times: Array) -> float:
    """A lower bound of the largest displacement coordinate: at the coordinate of the
    largest static displacement, ``max_t |d_m(t)| − bound(t) · S`` over ``times``
    (``d_m``: the chosen basis with its static correction); the bound is evaluated only
    at the times of the largest ``|d_m|`` that can still decide the maximum."""
    merged: dict[float, Array] = {}
    for t_j, F in jumps:
        merged[t_j] = merged.get(t_j, 0.0) + np.asarray(F, dtype=float)
    order = sorted(merged)
    projected = [basis.project(merged[t_j]) for t_j in order]
    coef = [g / basis.lam[:, None] for g in projected]
    statics = np.cumsum([basis.expand(g[None])[0] + part
                         for g, part in zip(coef, correction.jump_parts)], axis=0)
    _, p, c = np.unravel_index(int(np.argmax(np.abs(statics))), statics.shape)
    lam = basis.lam
    zero = np.zeros((lam.size, 1))                      # the one coordinate c
    response = ModalResponse(lam, gamma + beta * lam, zero, zero,
                             [(t_j, g[:, c:c + 1]) for t_j, g in zip(order, projected)], [])
    row = basis.phi[p]                          # a DenseBasis (automatic_basis)
    d = response(times)[0][:, :, 0] @ row + correction.coordinate(times, p, c)
    # max_t |d(t)| − bound(t)·S: the times by |d| falling, the bound evaluated a few at a
    # time until no time left can exceed the best (the bound is ≥ 0)
    size = np.abs(d)
    ranked = np.argsort(-size)
    best = -np.inf
    for start in range(0, ranked.size, 8):
        chunk = ranked[start:start + 8]
        if size[chunk[0]] <= best:
            break
        error = report["estimate"].relative(times[chunk]) * report["scale"]
        best = max(best, float(np.max(size[chunk] - error)))
    return best


def pointwise_factor(model: Model) -> float:
    """``c_∞ ≥ max_p √((M_r⁻¹)_pp)`` of the model (:func:`.mode_select.pointwise_bound`):
    for the parametric consistent mass ``M = μ G0u⊗G0v`` the diagonal of ``M⁻¹`` is the
    Kronecker product of the 1-D ones over ``μ``; cached per model."""
    if model not in _POINTWISE:
        M = model.matrices()[0]
        inverse = None
        if (model.physics == "parametric" and model.mass_matrix == "consistent"
                and model.gram_u is not None                # one patch: M = μ G0u⊗G0v
                and getattr(model.surface, "trim", None) is None):
            gu, gv = (np.diag(np.linalg.inv(g[0].toarray())) for g in (model.gram_u,
                                                                       model.gram_v))
            inverse = np.kron(gu, gv) / model.material.mass
        _POINTWISE[model] = mode_select.pointwise_bound(M, model.T, inverse)
    return _POINTWISE[model]

def truncation_request(model: Model, modes: int | None, omega_max: float | None
                       ) -> tuple[int | None, float | None]:
    """Checked ``modes`` (an integer in ``[1, n_free]``) and ``omega_max`` (finite, > 0)."""
    if modes is not None and omega_max is not None:
        raise InputError("give either modes=k or omega_max=, not both")
    if modes is not None:
        modes = check_count(modes, model.n_free)
    if omega_max is not None:
        try:
            omega_max = float(omega_max)
        except (TypeError, ValueError):
            raise InputError(f"omega_max must be a number, got {omega_max!r}") from None
        if not np.isfinite(omega_max) or omega_max <= 0:
            raise InputError(f"omega_max must be finite and > 0, got {omega_max}")
    return modes, omega_max

def _truncation(model: Model, basis: modal_basis.ModalBasis, spatial: tuple[list, list],
                d0: Array, v0: Array, correction: Any = None) -> tuple[Any, dict[str, Any]]:
    """Mode-acceleration correction and the truncation report of a truncated basis
    (``correction``: already computed with the basis, by the automatic mode count)."""
    M, _, K = model.matrices()
    report: dict[str, Any] = {
        "modes": basis.size, "n_free": model.n_free,
        "omega_max_kept": float(np.sqrt(basis.lam.max())),
        "omega_first_omitted": float(np.sqrt(basis.first_omitted)),
        "initial_residual": max(_outside(basis, M, d0), _outside(basis, M, v0)),
    }
    if not basis.can_solve_static:
        report.update(static_correction=False, omitted_static=float("nan"),
                      static_residual=float("nan"))
        return None, report
    if correction is not None:
        report.update(static_correction=True)
        return correction, report
    correction, indicators = modal_basis.mode_acceleration(basis, K, M, *spatial)
    report.update(static_correction=True, **indicators)
    return correction, report


def _outside(basis: modal_basis.ModalBasis, M: sp.spmatrix, x: Array) -> float:
    """Relative M-norm of the part of ``x`` outside the span of a basis."""
    norm = float(np.sqrt(np.sum(x * (M @ x))))
    if norm == 0.0:
        return 0.0
    rest = x - basis.expand(basis.project(M @ x)[None])[0]
    return float(np.sqrt(max(np.sum(rest * (M @ rest)), 0.0))) / norm


def check_count(k: int, available: int) -> int:
    if isinstance(k, bool) or not isinstance(k, (int, np.integer)) or k < 1:
        raise InputError(f"number of modes must be an integer >= 1, got {k!r}")
    if k > available:
        raise InputError(f"asked for {k} modes but the model has only {available} free "
                         "coordinates")
    return int(k)
