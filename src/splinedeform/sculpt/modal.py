"""Modal data for sculpting and the per-frame modal sum.

A push is a point force ``P`` at parameters ``(u, v)`` switched on at ``t_on`` and off at
``t_off`` (a step).  With mass-normalised modes ``Φ`` (``Φᵀ M Φ = I``) and modal damping
``c_i = γ/μ + β λ_i`` each mode obeys ``q_i'' + c_i q_i' + λ_i q_i = φ_i(u, v) P s(t)``; the
response from rest to a unit step at ``t = 0`` is, with roots ``r_± = -c/2 ± √(c²/4 - λ)``,

    g(τ) = (1 - (r_+ e^{r_- τ} - r_- e^{r_+ τ}) / (r_+ - r_-)) / λ        (τ >= 0)

(complex roots when under-damped).  A push contributes ``φ_i(u, v) P (g(t - t_on) -
g(t - t_off))`` and pushes superpose; the displacement of the sampled surface points is
``Φ_s q(t)`` with ``Φ_s = E T Φ`` the modes evaluated on the sample grid.  Nothing is
rebuilt for a push: only ``φ(u, v)``, one row of the evaluation of ``T Φ``, is needed.
The page evaluates the same formula in JavaScript from the arrays of :class:`SculptBasis`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError
from ..model import Model

Array = NDArray[np.float64]


@dataclass(frozen=True)
class Push:
    """Point force ``force`` at ``(u, v)`` acting for ``t_on <= t < t_off``."""

    u: float
    v: float
    force: tuple[float, float, float]
    t_on: float
    t_off: float = math.inf


@dataclass(frozen=True)
class SculptBasis:
    """Modes of a model sampled on a surface grid, with their frequencies and damping.

    Attributes
    ----------
    lam : (k,) eigenvalues ``λ_i = ω_i²`` (all > 0: rigid motions must be held).
    damping : (k,) modal damping ``c_i = γ/μ + β λ_i``.
    samples_u, samples_v : parameters of the ``(ru, rv)`` sample grid.
    phi_samples : (ru*rv, k) modes at the sample points, ``Φ_s = E T Φ``.
    """

    model: Model
    lam: Array
    damping: Array
    phi_net: Array
    samples_u: Array
    samples_v: Array
    phi_samples: Array

    def participation(self, u: float, v: float) -> Array:
        """Mode shapes at the grabbed point ``φ_i(u, v)``, shape ``(k,)``."""
        E = self.model.surface.evaluation_matrix(np.array([u]), np.array([v]))
        return np.asarray(E @ self.phi_net).ravel()

    def step_response(self, tau: Array) -> Array:
        """``g_i(τ)`` of every mode to a unit step at ``τ = 0``, shape ``tau.shape + (k,)``."""
        tau = np.asarray(tau, dtype=float)[..., None]
        half = self.damping / 2
        root = np.sqrt((half * half - self.lam).astype(complex))
        rp, rm = -half + root, -half - root
        t = np.maximum(tau, 0.0)
        g = (1 - (rp * np.exp(rm * t) - rm * np.exp(rp * t)) / (rp - rm)).real / self.lam
        return np.where(tau >= 0, g, 0.0)

    def modal(self, t: float, pushes: list[Push]) -> Array:
        """Modal coordinates ``q(t)``, shape ``(k, 3)``: the superposed push responses."""
        q = np.zeros((self.lam.size, 3))
        for push in pushes:
            weight = self.step_response(np.array(t - push.t_on))
            if math.isfinite(push.t_off):
                weight = weight - self.step_response(np.array(t - push.t_off))
            q += (self.participation(push.u, push.v) * weight)[:, None] * np.asarray(push.force)[None, :]
        return q

    def displacement(self, t: float, pushes: list[Push]) -> Array:
        """Displacement of the sample points at ``t``, shape ``(ru*rv, 3)``: ``Φ_s q(t)``."""
        return self.phi_samples @ self.modal(t, pushes)


def sculpt_basis(model: Model, resolution: int = 32, modes: int | None = None) -> SculptBasis:
    """Modes of ``model`` (all, or the lowest ``modes``) sampled on a ``resolution²`` grid."""
    lam, phi = model.eigen(modes)
    if lam.size == 0:
        raise InputError("the model has no free control points to sculpt")
    if np.min(lam) <= 1e-12 * max(np.max(lam), 1e-300):
        raise InputError("the model has rigid-body modes (zero frequency); hold at least one "
                         "edge (pinned or clamped) so that a push has a rest position")
    mat = model.material
    damping = mat.damping / mat.mass + mat.rayleigh * lam
    phi_net = np.asarray(model.constraints.T @ phi)
    u, v = model.surface.sample_parameters(resolution)
    uu, vv = np.meshgrid(u, v, indexing="ij")
    E = model.surface.evaluation_matrix(uu.ravel(), vv.ravel())
    return SculptBasis(model, lam, damping, phi_net, np.asarray(u), np.asarray(v),
                       np.asarray(E @ phi_net))
