"""Many load cases of one model read out from their modal coordinates, a few products for all.

A dynamic closed-form case on a complete modal basis (``Φᵀ M Φ = I``, ``Φᵀ K Φ = Λ``,
``d(t) = Φ q(t)`` exactly, no mode-acceleration part) needs its control net only through
linear maps of ``q``, so each figure of its row (:mod:`.measure`) comes from the modal
coordinates directly (DESIGN.md §1.4, §1.7):

- the loads ``F_r(t) = F_rest + Σ_i s_i(t) Tᵀ F_i`` of all cases of a chunk are projected in
  one product ``g = Φᵀ [F_rest, Tᵀ F_1, …]``; the modal coordinates are
  ``q(t) = Σ_i r_i(t) ⊙ g_i`` with the closed-form response ``r_i`` of the profile ``s_i``
  (``Σ_j Δs_j S(t − t_j)`` for piecewise-constant profiles, the harmonic response for
  ``sin(Ωt + φ)``), each response computed once for every case that shares it;
- kinetic ``½ Σ q̇²``, strain ``½ Σ λ q²`` and work ``Σ (Φᵀ F_r(t)) · q`` per frame;
- the surface samples ``X_f = E T Φ q_f`` (and the probes' ``E_p T Φ q_f``) with ``E T Φ``
  formed once per model and resolution, all frames of all cases of a chunk in one product.

:func:`prepare` says whether a case can be read out so (else the ordinary pipeline solves it:
numerical methods, static and modes solves, truncated bases, time-dependent fields, loads
rescaled by :mod:`~splinedeform.load_scale`, per-case outputs).
"""

from __future__ import annotations

from dataclasses import dataclass
from types import SimpleNamespace
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..budget import check as check_budget
from ..load_scale import load_scale
from ..loads import Harmonic, Profile, as_load
from ..modal_solve import _bound_applies
from ..model import Model
from ..pipeline import _domain_centre
from ..scenario import Built, Scenario, build_load
from ..scenario.build import _located, check_parameters
from ..solvers.analytic import harmonic_response, step_response
from ..solvers.forcing import ReducedForcing
from ..threads import owned
from .measure import figures

Array = NDArray[np.float64]

#: modal values ``frames × modes × 3 × cases`` held at once (as ModalSolution.chunk_entries)
CHUNK_ENTRIES = 4_000_000


@dataclass
class Prepared:
    """A case ready for the modal read-out: its frame times and its load's parts."""

    scenario: Scenario
    times: Array
    rest: Array | None                           # F_rest (n_free, 3), or None for 0
    parts: list[tuple[Profile, Array]]           # (s_i, Tᵀ F_i (n_free, 3))


def prepare(scenario: Scenario, built: Built, case_outputs: bool) -> Prepared | None:
    """The case's frame times and load parts when the modal read-out applies, else None
    (also when building its load fails: the ordinary path then reports the error)."""
    solve, model = scenario.solve, built.model
    if not isinstance(model, Model) or solve.kind != "dynamic" or \
            solve.method != "analytic" or (case_outputs and scenario.output.formats):
        return None                        # (a shell's modes move x, y and z together)
    try:
        if load_scale(scenario) != 1.0:
            return None
        check_parameters(scenario, built.surface)
        with _located(scenario, "load"):
            load = as_load(build_load(scenario))
        check_budget(scenario, model, None)
        terms = ReducedForcing(model.reduction, load).fixed_terms()
    except Exception:  # noqa: BLE001  (the ordinary path reports it with its key)
        return None
    if terms is None or not all((p.jumps() is not None or isinstance(p, Harmonic)) and
                                np.shape(f) == (model.n_free, 3) for p, f in terms[1]):
        return None
    zero = np.zeros((model.n_free, 3))
    harmonics = [p for p, _ in terms[1] if p.jumps() is None]
    # the analytic default takes all modes unless its mode count applies to this load
    if _bound_applies(model, ([], harmonics), zero, zero, "auto"):
        return None
    if not model.modal_basis("auto", None, None).complete:
        return None
    return Prepared(scenario, np.asarray(solve.frame_times(), dtype=float), *terms)


class ModalReadout:
    """The figures of prepared load cases of one model (see the module's description)."""

    def __init__(self, built: Built) -> None:
        model = built.model
        self.built = built
        self.basis = model.modal_basis("auto", None, None)
        self.lam = np.maximum(self.basis.lam, 0.0)
        physics = model.formulation
        self.c = physics.damping_rate + physics.rayleigh * self.lam
        self._maps: dict[Any, Array] = {}
        self._responses: dict[Any, Array] = {}

    @owned
    def figures(self, cases: list[Prepared]) -> list[dict[str, Any] | None]:
        """Each case's row figures (None for a case whose figures are not finite: the
        ordinary path then reports why), chunked to :data:`CHUNK_ENTRIES` modal values."""
        out: list[dict[str, Any] | None] = []
        per = max(1, CHUNK_ENTRIES // max(3 * self.basis.size * max(
            (c.times.size for c in cases), default=1), 1))
        for i in range(0, len(cases), per):
            out += self._chunk(cases[i:i + per])
        return out

    def _chunk(self, cases: list[Prepared]) -> list[dict[str, Any] | None]:
        fields = [f for case in cases for f in
                  ([] if case.rest is None else [case.rest]) + [v for _, v in case.parts]]
        modal = self.basis.project(np.concatenate(fields, axis=1)) if fields else None
        Q, V, W = [], [], []
        col = 0
        for case in cases:
            q = np.zeros((case.times.size, self.basis.size, 3))
            v = np.zeros_like(q)
            force = np.zeros_like(q)                  # Φᵀ F_r(t_f)
            terms = [] if case.rest is None else [(None, case.rest)]
            for profile, _ in terms + case.parts:
                g = modal[:, col:col + 3]
                col += 3
                r, dr = self._response(profile, case.times)
                q += r[..., None] * g
                v += dr[..., None] * g
                s = np.ones(case.times.size) if profile is None else \
                    np.asarray(profile(case.times), dtype=float)
                force += s[:, None, None] * g
            Q.append(q)
            V.append(v)
            W.append(np.einsum("fnc,fnc->f", force, q))
        return self._rows(cases, Q, V, W)

    def _response(self, profile: Profile | None, times: Array) -> tuple[Array, Array]:
        """``(r, ṙ)`` of shape (F, N): the modal response to ``s(t)`` applied from rest
        (``profile`` None: the rest force, on from ``t = 0``)."""
        key = (profile, times.tobytes())
        if key not in self._responses:
            lam, c, t = self.lam[None, :], self.c[None, :], times[:, None]
            if isinstance(profile, Harmonic):
                r, dr = harmonic_response(lam, c, profile.omega, profile.phase, t)
            else:
                jumps = [(0.0, 1.0)] if profile is None else profile.jumps()
                r, dr = np.zeros((times.size, lam.size)), np.zeros((times.size, lam.size))
                for t_j, ds in jumps:
                    s, ds_dt = step_response(lam, c, t - t_j)
                    r += ds * s
                    dr += ds * ds_dt
            self._responses[key] = (r, dr)
        return self._responses[key]

    def _map(self, key: Any, u: Array, v: Array, modal: bool = True) -> Any:
        """``E T Φ`` (dense, points × N) for the parameters ``u``, ``v``, or ``E T`` (sparse,
        points × n_free) when not ``modal``; formed once per model."""
        if (key, modal) not in self._maps:
            surface, T = self.built.surface, self.built.model.constraints.T
            ET = (surface.evaluation_matrix(u, v) @ T).tocsr()
            self._maps[key, modal] = np.ascontiguousarray(
                self.basis.project(ET.T.toarray()).T) if modal else ET
        return self._maps[key, modal]

    def _rows(self, cases: list[Prepared], Q: list[Array], V: list[Array],
              W: list[Array]) -> list[dict[str, Any] | None]:
        surface = self.built.surface
        model = self.built.model
        rows: list[dict[str, Any] | None] = []
        grids = self._samples(cases, Q)
        for case, q, v, work, grid in zip(cases, Q, V, W, grids):
            scenario = case.scenario
            probes = scenario.output.probes or (_domain_centre(surface),)
            at = np.asarray(probes, dtype=float)
            P = self._map(("probes", at.tobytes()), at[:, 0], at[:, 1])
            histories = np.einsum("pn,fnc->pfc", P, q)
            with np.errstate(over="ignore", invalid="ignore"):
                size = float(np.abs(grid).max(initial=0.0))
                scale = size if 0.0 < size < np.inf else 1.0
                per_frame = scale * np.linalg.norm(grid / scale, axis=-1).max(axis=0)
                kinetic = 0.5 * np.einsum("fnc,fnc->f", v, v)
                strain = 0.5 * np.einsum("n,fnc->f", self.lam, q * q)
            k = scenario.solve.modes
            omegas = model.frequencies(min(k, model.n_free)) if k > 0 else None
            result = SimpleNamespace(
                scenario=scenario, times=case.times, displacement_per_frame=per_frame,
                max_displacement=float(per_frame.max(initial=0.0)), omegas=omegas,
                energy={"kinetic": kinetic, "strain": strain,
                        "total": kinetic + strain - work},
                probes={f"p{i}": histories[i - 1] for i in range(1, len(probes) + 1)})
            arrays = [per_frame, kinetic, strain, work, histories]
            finite = all(np.all(np.isfinite(a)) for a in arrays)
            rows.append(figures(result) if finite else None)
        return rows

    def _samples(self, cases: list[Prepared], Q: list[Array]) -> list[Array]:
        """Each case's surface displacements ``(points, F, 3)`` on its output grid, the cases
        of one resolution in one product."""
        surface = self.built.surface
        out: list[Array | None] = [None] * len(cases)
        by_resolution: dict[Any, list[int]] = {}
        for i, case in enumerate(cases):
            by_resolution.setdefault(case.scenario.output.resolution, []).append(i)
        for resolution, index in by_resolution.items():
            u, v = surface.sample_parameters(resolution)
            u, v = np.repeat(u, v.size), np.tile(v, u.size)
            stacked = np.concatenate([np.moveaxis(Q[i], 1, 0).reshape(self.basis.size, -1)
                                      for i in index], axis=1)
            # E T Φ once, or Φ q per column: the cheaper of points × N and n_free × N
            if u.size < self.basis.n_free:
                X = self._map(("grid", repr(resolution)), u, v) @ stacked
            else:
                ET = self._map(("grid", repr(resolution)), u, v, modal=False)
                X = np.asarray(ET @ self.basis.expand(stacked[None])[0])
            col = 0
            for i in index:
                width = 3 * cases[i].times.size
                out[i] = X[:, col:col + width].reshape(u.size, -1, 3)
                col += width
        return out  # type: ignore[return-value]

