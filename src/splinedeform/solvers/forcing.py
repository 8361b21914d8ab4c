"""The load of a model reduced onto its free coordinates, as the solvers need it.

:class:`ReducedForcing` is a callable ``F_r(t)`` with the load's breakpoints (where the
integrators restart) and its modal terms (jumps and harmonics, for the closed-form path).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ..loads import Harmonic, Load, Profile
from .system import Reduction

Array = NDArray[np.float64]


class ReducedForcing:
    """The reduced load ``F_r(t) = F_rest + Σ_terms s(t) Tᵀ F_term(t)`` on a constraint map.

    ``reduction`` gives ``T``, the surface the load fields are evaluated on and
    ``F_rest = −Tᵀ K p0`` for a model without rest shape (else 0). Spatial vectors of loads
    whose field does not change in time are computed once.
    Callable: ``forcing(t) -> (n_free, columns)`` (``columns`` of the reduction).
    """

    def __init__(self, reduction: Reduction, load: Load):
        self.reduction = reduction
        self.terms = load.terms()
        self._fixed = [None if term.time_dependent_field
                       else self.reduction.reduce(self.reduction.field(term))
                       for term in self.terms]
        rest = self.reduction.rest_force
        self._rest = None if rest is None else np.array(rest, dtype=float)
        self.breakpoints = load.breakpoints()

    def _field(self, i: int, t: float) -> Array:
        fixed = self._fixed[i]
        if fixed is not None:
            return fixed
        return self.reduction.reduce(self.reduction.field(self.terms[i], t))

    def __call__(self, t: float) -> Array:
        out = np.zeros((self.reduction.n_free, self.reduction.columns)) if self._rest is None else self._rest.copy()
        for i, term in enumerate(self.terms):
            scale = float(term.profile(t))
            if scale:
                out += scale * self._field(i, t)
        return out

    def fixed_terms(self) -> tuple[Array | None, list[tuple[Profile, Array]]] | None:
        """``(F_rest, [(s_i, Tᵀ F_i)])`` when no field changes in time, so that
        ``F_r(t) = F_rest + Σ_i s_i(t) Tᵀ F_i`` (``F_rest`` None for 0); else None."""
        if any(fixed is None for fixed in self._fixed):
            return None
        return self._rest, [(term.profile, fixed) for term, fixed in zip(self.terms, self._fixed)]

    def modal_terms(self, phi: Array, t_end: float, samples: int
                    ) -> tuple[list[tuple[float, Array]], list[tuple[float, float, Array]]]:
        """Modal jumps ``(t_j, Φᵀ ΔF_j)`` and harmonic terms ``(Ω, φ, Φᵀ F)``.

        Time-dependent fields are sampled at ``samples`` interval midpoints on ``[0, t_end]``
        (piecewise constant in time, first-order accurate in the interval width).
        """
        jumps: list[tuple[float, Array]] = []
        harmonics: list[tuple[float, float, Array]] = []
        if self._rest is not None:
            jumps.append((0.0, phi.T @ self._rest))
        edges = np.linspace(0.0, t_end, int(samples) + 1)
        for i, term in enumerate(self.terms):
            jumps_of_profile = term.profile.jumps()
            if self._fixed[i] is not None and jumps_of_profile is not None:
                g = phi.T @ self._fixed[i]
                jumps += [(t_j, ds * g) for t_j, ds in jumps_of_profile]
            elif self._fixed[i] is not None and isinstance(term.profile, Harmonic):
                harmonics.append((term.profile.omega, term.profile.phase, phi.T @ self._fixed[i]))
            else:
                mids = 0.5 * (edges[:-1] + edges[1:])
                values = [phi.T @ (float(term.profile(tm)) * self._field(i, tm)) for tm in mids]
                previous = np.zeros_like(values[0])
                for t_j, value in zip(edges[:-1], values):
                    jumps.append((float(t_j), value - previous))
                    previous = value
        return jumps, harmonics
