"""Static correction of a truncated sculpting basis (mode acceleration), per grabbed point.

With only the lowest ``k`` modes the omitted ones still answer a held push almost
statically. Mode acceleration adds their static part: for a unit force at the sample
point ``a`` (reduced force ``F_a = Tᵀ E_aᵀ``)

    r_a = E_s T (K_r⁻¹ F_a - Φ Λ⁻¹ Φᵀ F_a)          (one scalar per sample point)

and the displacement of the samples becomes ``Φ_s q(t) + Σ_a r_a ⊗ P_a(t)`` with ``P_a(t)``
the force held at ``a`` at time ``t``. This is the correction of
``Model.dynamic(..., modes=k)``; it makes the static limit of a held push exact. One sparse
back-substitution (the factor of ``K_r`` is kept) and one sparse product per grabbed
point, computed when the point is first grabbed, never per frame.

Added at once, ``r_a ⊗ P_a`` is a static part the dynamics may not have reached: under
heavy damping (``γ = 10⁸``) the omitted modes creep, and the instant correction dented the
sheet by 0.026 where the whole dynamics gives 1.5e-6 after 0.6 s. The page therefore adds
``r_a ⊗ z_a(t)`` with ``z_a`` following the force through one mode of its own,

    z_a'' + c* z_a' + λ* z_a = λ* P_a(t),        (λ*, c*) = (λ_k, c_k),

the highest kept mode: every omitted mode has ``λ_j ≥ λ_k``, and its unit step reaches
``λ_j g_j(τ) ≥ λ_k g_k(τ)`` of its static part when over-damped, so the correction never
runs ahead of the omitted modes; the static limit ``z_a = P_a`` is unchanged
(:func:`follower` is the Python twin of the page's follower).
"""

from __future__ import annotations

from typing import Any

import numpy as np
import scipy.sparse.linalg as spla
from numpy.typing import NDArray

from ..errors import SingularSystemError
from .modal import SculptBasis

Array = NDArray[np.float64]


class StaticCorrection:
    """Residual flexibility columns ``r_a`` of a :class:`SculptBasis` (cached per sample)."""

    def __init__(self, basis: SculptBasis, phi: Array):
        self.basis = basis
        self.phi = phi                                   # reduced modes (n_free, k)
        self.complete = basis.lam.size == basis.model.n_free
        self._T = basis.model.constraints.T
        self._samples = basis.sample_count
        self._factor: Any = None                         # factor of K_r and the sample
        self._E: Any = None                              # evaluation: at the first grab
        self._cache: dict[int, Array] = {}

    @property
    def samples(self) -> int:
        return int(self._samples)

    def _prepare(self) -> None:
        model = self.basis.model
        self._factor = spla.splu(model.matrices()[2])
        self._E = self.basis.sample_matrix()

    def column(self, index: int) -> Array:
        """``r_a`` for the sample point ``index`` (row-major over the ``(ru, rv)`` grid, patch
        after patch)."""
        if index in self._cache:
            return self._cache[index]
        if self.complete:
            column = np.zeros(self.samples)
        else:
            if self._factor is None:
                self._prepare()
            F = np.asarray(self._T.T @ self._E[index].toarray().ravel())
            full = self._factor.solve(F)
            if not np.all(np.isfinite(full)):
                raise SingularSystemError("the stiffness matrix is singular: no static correction")
            part = full - self.phi @ ((self.phi.T @ F) / self.basis.lam)
            column = np.asarray(self._E @ (self._T @ part)).ravel()
        self._cache[index] = column
        return column

    def displacement(self, held: dict[int, tuple[float, float, float]]) -> Array:
        """``Σ_a r_a ⊗ P_a`` for the forces ``held`` at sample points, ``(samples, 3)``."""
        out = np.zeros((self.samples, 3))
        for index, force in held.items():
            out += self.column(index)[:, None] * np.asarray(force, dtype=float)[None, :]
        return out


def follower(basis: SculptBasis, steps: list[tuple[tuple[float, float, float], float, float]],
             t: float) -> Array:
    """``z_a(t)`` of one grabbed sample for the force ``steps`` ``(P, t_on, t_off)`` held
    there, shape ``(3,)``: the Python twin of the page's follower.

    ``z_a = Σ P (h(t − t_on) − h(t − t_off))`` with ``h(τ) = λ_k g_k(τ)`` the unit step
    response of the highest kept mode scaled to its static value 1, evaluated by the
    closed form of :func:`.state.advance` (no cancellation when heavily damped); the
    correction drawn is ``r_a ⊗ z_a(t)`` (see the module text).
    """
    from .state import advance

    lam, damping = basis.lam[-1:], basis.damping[-1:]

    def h(tau: float) -> float:
        if tau <= 0:
            return 0.0
        unit = np.full((1, 3), lam[0])
        return float(advance(lam, damping, np.zeros((1, 3)), np.zeros((1, 3)), unit, tau)[0][0, 0])

    z = np.zeros(3)
    for force, t_on, t_off in steps:
        weight = h(t - t_on) - (h(t - t_off) if np.isfinite(t_off) else 0.0)
        z += weight * np.asarray(force, dtype=float)
    return z


def offline_data(basis: SculptBasis) -> dict[str, Any] | None:
    """What a page needs to compute ``r_a`` itself, without the server (a saved page).

    ``K_r`` reordered by reverse Cuthill–McKee (a narrow profile for the page's envelope
    Cholesky factorisation), its lower triangle in CSR, and ``G = E_s T`` with its columns
    in the same order, CSR; the page solves ``K_r x = G[a]ᵀ`` and forms
    ``r_a = G x − Φ_s Λ⁻¹ Φ_s[a]ᵀ`` (``Φᵀ F_a = Φ_s[a]``, the modes at the grabbed
    sample). Indices int32, values float64; None when every mode is kept (no correction).
    """
    import scipy.sparse as sp
    from scipy.sparse.csgraph import reverse_cuthill_mckee

    from .export import _b64

    if basis.lam.size == basis.model.n_free:
        return None
    model = basis.model
    K = sp.csr_matrix(model.matrices()[2])
    order = reverse_cuthill_mckee(K, symmetric_mode=True)
    lower = sp.tril(K[order][:, order], format="csr")
    lower.sort_indices()
    G = sp.csr_matrix(basis.sample_matrix() @ model.constraints.T)[:, order]
    G.sort_indices()
    return {"n": int(K.shape[0]),
            "k_indptr": _b64(lower.indptr, "<i4"), "k_indices": _b64(lower.indices, "<i4"),
            "k_values": _b64(lower.data, "<f8"),
            "g_indptr": _b64(G.indptr, "<i4"), "g_indices": _b64(G.indices, "<i4"),
            "g_values": _b64(G.data, "<f8")}


def static_correction(basis: SculptBasis) -> StaticCorrection:
    """The correction of ``basis`` (zero when it keeps every mode)."""
    lam, phi = basis.model.eigen(basis.lam.size)
    return StaticCorrection(basis, np.asarray(phi))
