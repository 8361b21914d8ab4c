"""Eigen-solution strategies for ``K_r φ = λ M_r φ``, ``Φᵀ M_r Φ = I`` (DESIGN.md §1.7).

A :class:`ModalBasis` holds eigenvalues ``λ`` and applies ``Φ`` and ``Φᵀ`` to coordinate
arrays without the caller knowing how ``Φ`` is stored:

* :class:`DenseBasis` — an explicit ``(n_free, N)`` matrix: all modes from dense ``eigh``
  (the reference for small and medium nets, :func:`dense_basis`), or the lowest ``k``
  from sparse shift-invert Lanczos (:func:`sparse_basis`).
* :class:`SeparableBasis` — with ``w11 = 0``, consistent mass and per-edge constraints
  (``T = T_u ⊗ T_v``, also a rectangular free region)::

      K_r = A_u ⊗ B_v + B_u ⊗ A_v,    M_r = μ B_u ⊗ B_v,
      B = Tᵀ G0 T,  A_u = T_uᵀ (w10 G1u + w20 G2u) T_u,  A_v = T_vᵀ (w01 G1v + w02 G2v) T_v.

  The 1-D problems ``A_u x = α B_u x`` and ``A_v y = β B_v y`` give every mode as
  ``φ_ij = (x_i ⊗ y_j)/√μ`` with ``λ_ij = (α_i + β_j)/μ``; ``Φ Q`` is ``Φ_u Q Φ_vᵀ/√μ``
  per coordinate (two small matrix products), ``O(n^{3/2})`` for ``n`` free
  coordinates instead of ``O(n³)``. The lumped mass ``μ D_u ⊗ D_v`` does not share the
  factors ``G0`` of ``K``, so it has no such form and uses the general path.

Every basis also solves the static problem ``K_r d = F`` exactly (:meth:`ModalBasis.static`)
so that a truncated basis can add the mode-acceleration correction
``K⁻¹F − Φ Λ⁻¹ Φᵀ F`` (:mod:`.mode_acceleration`).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from numpy.typing import NDArray

from ..errors import InputError, SingularSystemError
from . import kronecker_eigen
from .mode_acceleration import StaticCorrection, mode_acceleration  # noqa: F401 (public here too)
from .rigid import check_resolved, count_by_gap, direction_rigid

if TYPE_CHECKING:
    from ..model import Model

Array = NDArray[np.float64]
EIGENSOLVERS = ("auto", "dense", "separable", "sparse")
DENSE_LIMIT = 1024
"""Up to this many free coordinates ``auto`` uses dense ``eigh`` (the reference path)."""
DENSE_MAX = 8000
"""Above this many free coordinates all modes of a general net are refused (O(n³), n² memory)."""


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


# --------------------------------------------------------------------------- strategies
DEFAULT_ADVICE = "Raise the smallest weight, or use fewer cells or a lower degree"


def dense_basis(K: sp.spmatrix, M: sp.spmatrix, rigid: int | None = None,
                advice: str = DEFAULT_ADVICE) -> DenseBasis:
    """All modes by dense ``eigh(K_r, M_r)`` (LAPACK ``sygvd``).

    The ``rigid`` lowest eigenvalues (the dimension of ``null K_r``, decided from the
    constraints by :mod:`.rigid`; ``None``: counted at round-off level behind a clear gap)
    are set to 0; the rest must be resolved (:func:`.rigid.check_resolved`).
    """
    lam, phi = sla.eigh(K.toarray(), M.toarray(), check_finite=False)
    if rigid is None:
        rigid = count_by_gap(lam, "dense eigen-solution")
    lam = check_resolved(lam, rigid, "dense eigen-solution", advice)
    return DenseBasis(lam, phi, "dense", True)


def kronecker_basis(model: Model, rigid: int | None, advice: str = DEFAULT_ADVICE
                    ) -> DenseBasis:
    """All modes by the Kronecker reduction to standard form (:mod:`.kronecker_eigen`)."""
    lam, phi = kronecker_eigen.eigenpairs(model)
    if rigid is None:
        rigid = count_by_gap(lam, "dense eigen-solution")
    return DenseBasis(check_resolved(lam, rigid, "dense eigen-solution", advice), phi,
                      "dense", True)


def separable_reason(model: Model) -> str | None:
    """Why the separable fast path does not apply to ``model`` (``None`` if it does)."""
    if getattr(model, "physics", "parametric") != "parametric":
        return "the surface metric varies over the parameters (no Kronecker factors)"
    if model.material.w11 != 0:
        return "the twist weight w11 is not 0 (its term G1u⊗G1v couples the directions)"
    if model.mass_matrix != "consistent":
        return "the lumped mass does not share the Gram factors G0 of the stiffness"
    if model.constraints.T_u is None or model.constraints.T_v is None:
        return "the fixed control points do not leave a rectangular free region"
    return None


def separable_matrices(model: Model) -> tuple[Array, Array, Array, Array]:
    """Reduced 1-D matrices ``(A_u, B_u, A_v, B_v)`` with ``K_r = A_u⊗B_v + B_u⊗A_v``, ``M_r = μ B_u⊗B_v``."""
    m, c = model.material, model.constraints
    gu, gv = model.gram_u, model.gram_v

    def reduce(T: sp.spmatrix, G: sp.spmatrix) -> Array:
        return np.asarray((T.T @ G @ T).toarray())

    def tension_bending(g: list[sp.spmatrix], w1: float, w2: float) -> sp.spmatrix:
        out = w1 * g[1]
        return out + w2 * g[2] if w2 else out

    A_u = reduce(c.T_u, tension_bending(gu, m.w10, m.w20))
    A_v = reduce(c.T_v, tension_bending(gv, m.w01, m.w02))
    return A_u, reduce(c.T_u, gu[0]), A_v, reduce(c.T_v, gv[0])


def separable_basis(model: Model) -> SeparableBasis:
    """All modes from the two 1-D generalised eigenproblems (see the module docstring)."""
    reason = separable_reason(model)
    if reason is not None:
        raise InputError(f"the separable eigensolver does not apply: {reason}; use "
                         "eigensolver='dense' or 'sparse'")
    A_u, B_u, A_v, B_v = separable_matrices(model)
    m, c = model.material, model.constraints
    alpha, phi_u = sla.eigh(A_u, B_u, check_finite=False)
    beta, phi_v = sla.eigh(A_v, B_v, check_finite=False)
    orders_u = [a for w, a in ((m.w10, 1), (m.w20, 2)) if w]
    orders_v = [a for w, a in ((m.w01, 1), (m.w02, 2)) if w]
    alpha = check_resolved(alpha, direction_rigid(model.surface.basis_u, c.T_u, orders_u),
                           "separable eigen-solution in u", DEFAULT_ADVICE)
    beta = check_resolved(beta, direction_rigid(model.surface.basis_v, c.T_v, orders_v),
                          "separable eigen-solution in v", DEFAULT_ADVICE)
    return SeparableBasis(alpha, phi_u, beta, phi_v, model.material.mass)


def stiffness_factorisation(K: sp.spmatrix, shift: float = 0.0, M: sp.spmatrix | None = None
                            ) -> Any:
    """Sparse LU of ``K - shift M`` (fill-reducing ordering for symmetric matrices)."""
    A = K if shift == 0.0 else K - shift * M
    try:
        return spla.splu(sp.csc_matrix(A), permc_spec="MMD_AT_PLUS_A")
    except RuntimeError:
        raise SingularSystemError(
            "the stiffness matrix is singular (some deformation costs no energy): constrain "
            "an edge or some control points, or add weights") from None


def _eigsh(K: sp.spmatrix, M: sp.spmatrix, k: int, shift: float, lu: Any) -> tuple[Array, Array]:
    n = K.shape[0]
    op = spla.LinearOperator((n, n), matvec=lu.solve, dtype=float)
    lam, phi = spla.eigsh(K, k=k, M=M, sigma=shift, which="LM", OPinv=op)
    order = np.argsort(lam)
    lam, phi = lam[order], phi[:, order]
    phi = phi / np.sqrt(np.einsum("ik,ik->k", phi, M @ phi))[None, :]
    return _zero_small(lam), phi


def sparse_basis(K: sp.spmatrix, M: sp.spmatrix, k: int | None = None,
                 omega_max: float | None = None, rigid: int | None = 0,
                 advice: str = DEFAULT_ADVICE) -> DenseBasis:
    """Lowest modes by shift-invert Lanczos (``eigsh`` with a sparse LU of ``K - σM``).

    ``k`` modes, or all with ``ω <= omega_max`` (found by doubling the request). One mode more
    than kept is computed so that the first omitted frequency is known. Without rigid modes
    (``rigid = 0``, the dimension of ``null K_r`` from :mod:`.rigid`) ``σ = 0`` and the LU of
    ``K`` is kept for the static part; with rigid modes (or ``None``, unknown: counted at
    round-off level behind a gap) ``K`` is singular, a small negative shift is used and
    there is no static solve. The ``rigid`` lowest eigenvalues are set to 0 and the rest
    checked against ``λ_max ≈ max K_ii/M_ii`` (:func:`.rigid.check_resolved`).
    """
    n = K.shape[0]
    unconstrained = rigid != 0
    if unconstrained:
        scale = float(np.mean(K.diagonal() / M.diagonal()))
        shift = -1e-6 * scale
    else:
        shift = 0.0
    lu = stiffness_factorisation(K, shift, M)
    solve = None if unconstrained else lu.solve
    if omega_max is not None:
        want = min(32, n - 2)
        while True:
            lam, phi = _eigsh(K, M, want, shift, lu)
            if lam[-1] > omega_max**2 or want >= n - 2:
                break
            want = min(2 * want, n - 2)
        k = int(np.searchsorted(lam, omega_max**2, side="right"))
        if k == 0:
            raise InputError(f"no mode has ω <= omega_max = {omega_max:g} (lowest ω = "
                             f"{np.sqrt(lam[0]):g})")
    else:
        assert k is not None
        lam, phi = _eigsh(K, M, min(k + 1, n - 1), shift, lu)
    top = float(np.max(K.diagonal() / M.diagonal()))       # a Rayleigh quotient <= λ_max
    if rigid is None:
        rigid = count_by_gap(lam, "sparse eigen-solution", top)
    lam = check_resolved(lam, min(rigid, lam.size), "sparse eigen-solution", advice, top)
    first = lam[k] if k < lam.size else np.inf
    return DenseBasis(lam[:k], phi[:, :k], "sparse", k == n, solve, first)


def _dense_cost_note(n: int) -> str:
    return (f"all {n} modes of a general net need a dense eigen-decomposition "
            f"(O(n³) time, {8 * n * n / 2**30:.2g} GiB per matrix)")


def choose(model: Model, eigensolver: str = "auto", truncated: bool = False) -> str:
    """The strategy for a model: ``dense``, ``separable`` or ``sparse``.

    ``auto``: dense ``eigh`` up to :data:`DENSE_LIMIT` free coordinates (the reference);
    above it the separable factors when they apply; otherwise sparse Lanczos when only the
    lowest modes are wanted (``truncated``) and dense up to :data:`DENSE_MAX`.
    """
    if eigensolver not in EIGENSOLVERS:
        raise InputError(f"unknown eigensolver {eigensolver!r}; choose one of {EIGENSOLVERS}")
    n = model.n_free
    if eigensolver != "auto":
        if eigensolver == "sparse" and not truncated:
            raise InputError("the sparse eigensolver computes the lowest modes only: give "
                             "modes=k or omega_max=")
        if eigensolver == "dense" and n > DENSE_MAX:
            raise InputError(_dense_cost_note(n) + f"; the limit is {DENSE_MAX}. Use "
                             "modes=k or omega_max= (sparse Lanczos)")
        return eigensolver
    if n <= DENSE_LIMIT:
        return "dense"
    if separable_reason(model) is None:
        return "separable"
    if truncated:
        return "sparse"
    if n <= DENSE_MAX:
        return "dense"
    raise InputError(_dense_cost_note(n) + f", more than the limit {DENSE_MAX}: give "
                     "modes=k or omega_max= for the lowest modes with the exact static "
                     "correction (mode acceleration)")


def truncate(basis: ModalBasis, k: int | None, omega_max: float | None
             ) -> ModalBasis:
    """The lowest ``k`` modes (or those with ``ω <= omega_max``) of a complete basis."""
    order = np.argsort(basis.lam, kind="stable")
    if omega_max is not None:
        k = int(np.searchsorted(basis.lam[order], omega_max**2, side="right"))
        if k == 0:
            raise InputError(f"no mode has ω <= omega_max = {omega_max:g} (lowest ω = "
                             f"{np.sqrt(basis.lam[order[0]]):g})")
    assert k is not None
    if isinstance(basis, SeparableBasis):
        return basis.restricted(np.sort(order[:k]))
    assert isinstance(basis, DenseBasis)
    return basis.truncated(k, basis.modal_static)


def eigen_residual(K: sp.spmatrix, M: sp.spmatrix, basis: ModalBasis, sample: int = 64) -> float:
    """``max_i ‖K φ_i - λ_i M φ_i‖ / ‖K φ_i‖`` over up to ``sample`` modes spread over the spectrum."""
    order = np.argsort(basis.lam, kind="stable")
    pick = order[np.unique(np.linspace(0, order.size - 1, min(sample, order.size)).astype(int))]
    phi = basis.columns(pick)
    Kp = K @ phi
    res = np.linalg.norm(Kp - (M @ phi) * basis.lam[pick], axis=0)
    return float(np.max(res / np.maximum(np.linalg.norm(Kp, axis=0), 1e-300)))
