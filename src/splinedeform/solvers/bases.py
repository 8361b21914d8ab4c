"""Modal bases: eigenvalues ``λ`` and the maps ``Φ``, ``Φᵀ`` of ``K_r φ = λ M_r φ`` (DESIGN.md §1.7).

A :class:`ModalBasis` holds eigenvalues ``λ`` with ``Φᵀ M_r Φ = I`` and applies ``Φ`` and
``Φᵀ`` to coordinate arrays without the caller knowing how ``Φ`` is stored:

* :class:`DenseBasis` — an explicit ``(n_free, N)`` matrix (all modes from dense ``eigh``, or
  the lowest ``k`` from sparse Lanczos; built in :mod:`.modal_basis`).
* :class:`SeparableBasis` — Kronecker-product modes ``φ_ij = (x_i ⊗ y_j)/√μ`` with
  ``λ_ij = (α_i + β_j)/μ`` from two 1-D eigenproblems; ``Φ Q`` is ``Φ_u Q Φ_vᵀ/√μ`` per
  coordinate (two small matrix products), ``O(n^{3/2})`` for ``n`` free coordinates.

Every basis also solves the static problem ``K_r d = F`` exactly (:meth:`ModalBasis.static`)
so that a truncated basis can add the mode-acceleration correction
``K⁻¹F − Φ Λ⁻¹ Φᵀ F`` (:mod:`.mode_acceleration`).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

from ..errors import InputError

Array = NDArray[np.float64]


def _zero_small(lam: Array) -> Array:
    """Clip round-off negatives to 0 (rigid motions have ``λ = 0``)."""
    return np.maximum(lam, 0.0)


class ModalBasis:
    """Modes ``Φ`` with ``Φᵀ M_r Φ = I`` and ``Φᵀ K_r Φ = diag(λ)``.

    Attributes
    ----------
    lam : ndarray (N,)
        Eigenvalues in the basis' own order (ascending for dense bases).
    kind : str
        ``"dense"``, ``"sparse"`` or ``"separable"``.
    complete : bool
        Whether the basis holds all ``n_free`` modes.
    """

    lam: Array
    kind: str
    complete: bool
    n_free: int

    @property
    def size(self) -> int:
        """Number of modes ``N``."""
        return int(self.lam.size)

    def project(self, F: Array) -> Array:
        """Modal forces ``Φᵀ F`` for ``F`` of shape ``(n_free, c)`` → ``(N, c)``."""
        raise NotImplementedError

    def expand(self, Q: Array) -> Array:
        """``Φ Q`` for modal coordinates ``Q`` of shape ``(F, N, c)`` → ``(F, n_free, c)``."""
        raise NotImplementedError

    def columns(self, index: Array) -> Array:
        """Explicit mode vectors ``Φ[:, index]``, shape ``(n_free, len(index))``."""
        raise NotImplementedError

    def static(self, F: Array) -> Array:
        """Exact ``K_r⁻¹ F`` (``F`` of shape ``(n_free, c)``); rigid modes get no response."""
        raise NotImplementedError

    @property
    def can_solve_static(self) -> bool:
        """Whether :meth:`static` is available (not for a sparse basis of a free surface)."""
        return True

    def modal_static(self, F: Array) -> Array:
        """Static response carried by the basis: ``Φ Λ⁺ Φᵀ F``."""
        g = self.project(F)
        inv = np.divide(1.0, self.lam, out=np.zeros_like(self.lam), where=self.lam > 0)
        return self.expand((inv[:, None] * g)[None])[0]


class DenseBasis(ModalBasis):
    """An explicit mode matrix ``phi`` of shape ``(n_free, N)``.

    Parameters
    ----------
    lam, phi : the eigenpairs (ascending ``lam``).
    solve : callable, optional
        ``K_r⁻¹`` for :meth:`static` when the basis is truncated (a sparse factorisation).
    first_omitted : float, optional
        The lowest eigenvalue left out of a truncated basis (``inf`` if none).
    """

    def __init__(self, lam: Array, phi: Array, kind: str = "dense", complete: bool = True,
                 solve: Callable[[Array], Array] | None = None,
                 first_omitted: float = np.inf):
        self.lam = np.asarray(lam, dtype=float)
        self.phi = np.asarray(phi, dtype=float)
        self.kind = kind
        self.complete = complete
        self.n_free = self.phi.shape[0]
        self._solve = solve
        self.first_omitted = float(first_omitted)

    def project(self, F: Array) -> Array:
        return self.phi.T @ F

    def expand(self, Q: Array) -> Array:
        F, N, c = Q.shape
        flat = np.ascontiguousarray(Q.transpose(1, 0, 2)).reshape(N, F * c)
        return (self.phi @ flat).reshape(self.n_free, F, c).transpose(1, 0, 2)

    def columns(self, index: Array) -> Array:
        return self.phi[:, np.asarray(index)]

    def static(self, F: Array) -> Array:
        if self.complete:
            return self.modal_static(F)
        if self._solve is None:
            raise InputError("this truncated basis has no stiffness factorisation for K⁻¹F")
        return np.asarray(self._solve(F))

    @property
    def can_solve_static(self) -> bool:
        return self.complete or self._solve is not None

    def truncated(self, k: int, solve: Callable[[Array], Array]) -> DenseBasis:
        """The lowest ``k`` modes, keeping ``solve = K_r⁻¹`` for the static part."""
        first = self.lam[k] if k < self.size else self.first_omitted
        return DenseBasis(self.lam[:k], self.phi[:, :k], self.kind, k == self.n_free and
                          self.complete, solve, first)


class SeparableBasis(ModalBasis):
    """Kronecker-product modes ``φ_ij = (x_i ⊗ y_j)/√μ``, ``λ_ij = (α_i + β_j)/μ``.

    Parameters
    ----------
    alpha, phi_u : 1-D eigenpairs of ``A_u x = α B_u x`` (``phi_uᵀ B_u phi_u = I``).
    beta, phi_v : the same in ``v``.
    mass : float
        ``μ``.
    keep : int array, optional
        Flat indices ``i n_v' + j`` of the modes kept (a truncated basis); default all.
    """

    kind = "separable"

    def __init__(self, alpha: Array, phi_u: Array, beta: Array, phi_v: Array, mass: float,
                 keep: Array | None = None):
        self.alpha, self.phi_u = np.asarray(alpha, float), np.asarray(phi_u, float)
        self.beta, self.phi_v = np.asarray(beta, float), np.asarray(phi_v, float)
        self.mass = float(mass)
        self.shape = (self.alpha.size, self.beta.size)
        self.n_free = self.phi_u.shape[0] * self.phi_v.shape[0]
        self.lam_all = _zero_small((self.alpha[:, None] + self.beta[None, :]).ravel() / self.mass)
        self.keep = None if keep is None else np.asarray(keep, dtype=np.int64)
        self.lam = self.lam_all if self.keep is None else self.lam_all[self.keep]
        self.complete = self.keep is None or self.keep.size == self.lam_all.size
        omitted = (np.delete(self.lam_all, self.keep) if self.keep is not None
                   else np.empty(0))
        self.first_omitted = float(omitted.min()) if omitted.size else np.inf

    def restricted(self, keep: Array) -> SeparableBasis:
        """The same factors with only the modes ``keep`` (flat indices)."""
        return SeparableBasis(self.alpha, self.phi_u, self.beta, self.phi_v, self.mass, keep)

    def _grid_project(self, F: Array) -> Array:
        """``Φ_uᵀ F_c Φ_v / √μ`` for every column ``c``, flattened → ``(n_u' n_v', c)``."""
        nu, nv = self.phi_u.shape[0], self.phi_v.shape[0]
        c = F.shape[1]
        grid = F.reshape(nu, nv * c)
        left = (self.phi_u.T @ grid).reshape(self.shape[0], nv, c)            # (a, nv, c)
        right = np.ascontiguousarray(left.transpose(0, 2, 1)).reshape(-1, nv) @ self.phi_v
        out = right.reshape(self.shape[0], c, self.shape[1]).transpose(0, 2, 1)
        return out.reshape(-1, c) / np.sqrt(self.mass)

    def project(self, F: Array) -> Array:
        full = self._grid_project(np.asarray(F, dtype=float))
        return full if self.keep is None else full[self.keep]

    def _grid_expand(self, G: Array) -> Array:
        """``Φ_u G_fc Φ_vᵀ / √μ`` for ``G`` of shape ``(F, n_u', n_v', c)`` → ``(F, n_free, c)``."""
        F, a, b, c = G.shape
        nu, nv = self.phi_u.shape[0], self.phi_v.shape[0]
        cols = np.ascontiguousarray(G.transpose(0, 1, 3, 2)).reshape(-1, b) @ self.phi_v.T
        rows = np.matmul(self.phi_u, cols.reshape(F, a, c * nv))              # (F, nu, c*nv)
        out = rows.reshape(F, nu, c, nv).transpose(0, 1, 3, 2).reshape(F, nu * nv, c)
        return out / np.sqrt(self.mass)

    def expand(self, Q: Array) -> Array:
        F, _, c = Q.shape
        if self.keep is None:
            grid = Q.reshape(F, self.shape[0], self.shape[1], c)
        else:
            grid = np.zeros((F, self.lam_all.size, c))
            grid[:, self.keep] = Q
            grid = grid.reshape(F, self.shape[0], self.shape[1], c)
        return self._grid_expand(grid)

    def columns(self, index: Array) -> Array:
        flat = np.asarray(index) if self.keep is None else self.keep[np.asarray(index)]
        i, j = np.divmod(flat, self.shape[1])
        cols = self.phi_u[:, i][:, None, :] * self.phi_v[:, j][None, :, :]
        return cols.reshape(self.n_free, flat.size) / np.sqrt(self.mass)

    def static(self, F: Array) -> Array:
        g = self._grid_project(np.asarray(F, dtype=float))
        inv = np.divide(1.0, self.lam_all, out=np.zeros_like(self.lam_all),
                        where=self.lam_all > 0)
        c = g.shape[1]
        return self._grid_expand((inv[:, None] * g).reshape((1,) + self.shape + (c,)))[0]
