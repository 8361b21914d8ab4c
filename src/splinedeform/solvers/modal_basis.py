"""Eigen-solution strategies for ``K_r φ = λ M_r φ``, ``Φᵀ M_r Φ = I`` (DESIGN.md §1.7).

Each strategy takes matrices (or their Kronecker factors) and returns a
:class:`~.bases.ModalBasis`:

* :func:`dense_basis` — all modes by dense ``eigh`` (the reference for small and medium nets);
* :func:`kronecker_basis` — all modes by the Kronecker reduction to standard form
  (:mod:`.kronecker_eigen`) when ``T = T_u ⊗ T_v`` and the mass is consistent;
* :func:`separable_basis` — with ``w11 = 0`` as well::

      K_r = A_u ⊗ B_v + B_u ⊗ A_v,    M_r = μ B_u ⊗ B_v,
      B = Tᵀ G0 T,  A_u = T_uᵀ (w10 G1u + w20 G2u) T_u,  A_v = T_vᵀ (w01 G1v + w02 G2v) T_v.

  The 1-D problems ``A_u x = α B_u x`` and ``A_v y = β B_v y`` give every mode as
  ``φ_ij = (x_i ⊗ y_j)/√μ`` with ``λ_ij = (α_i + β_j)/μ``, ``O(n^{3/2})`` for ``n`` free
  coordinates instead of ``O(n³)``. The lumped mass ``μ D_u ⊗ D_v`` does not share the
  factors ``G0`` of ``K``, so it has no such form and uses the general path;
* :func:`sparse_basis` — the lowest ``k`` modes by shift-invert Lanczos.

:func:`choose` picks one from the size of the problem. The bases and the mode-acceleration
names are re-exported here (``ModalBasis``, ``DenseBasis``, ``SeparableBasis``,
``StaticCorrection``, ``mode_acceleration``).
"""

from __future__ import annotations

from typing import Any

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from numpy.typing import NDArray

from ..errors import InputError, SingularSystemError
from . import kronecker_eigen
from .bases import DenseBasis, ModalBasis, SeparableBasis, _zero_small  # noqa: F401 (public here too)
from .mode_acceleration import StaticCorrection, mode_acceleration  # noqa: F401 (public here too)
from .factor import band_cholesky
from .eigen_trust import GUARDS, check_by_residual, refine_doubtful
from .rigid import check_resolved, count_by_gap
from .sparse_eigen import BlockLanczos, factorise
from .system import KroneckerFactors

Array = NDArray[np.float64]
EIGENSOLVERS = ("auto", "dense", "separable", "sparse")
DENSE_LIMIT = 1024
"""Up to this many free coordinates ``auto`` uses dense ``eigh`` (the reference path)."""
DENSE_MAX = 8000
"""Above this many free coordinates all modes of a general net are refused (O(n³), n² memory)."""


DEFAULT_ADVICE = "Raise the smallest weight, or use fewer cells or a lower degree"


def _resolved(K: sp.spmatrix, M: sp.spmatrix, lam: Array, phi: Array, rigid: int,
              what: str, advice: str, top: float | None, guard: str,
              mass_solve: Any | None = None) -> Array:
    """``lam`` with its rigid part zeroed, checked by ``guard`` (:data:`GUARDS`):
    ``condition`` (:func:`.rigid.check_resolved`), ``residual`` or ``off``
    (:func:`.eigen_trust.check_by_residual`)."""
    if guard not in GUARDS:
        raise InputError(f"guard must be one of {GUARDS}, got {guard!r}")
    if guard == "condition":
        return check_resolved(lam, rigid, what, advice, top)
    return check_by_residual(K, M, lam, phi, rigid, what, advice, top, guard, mass_solve)


def dense_basis(K: sp.spmatrix, M: sp.spmatrix, rigid: int | None = None,
                advice: str = DEFAULT_ADVICE, guard: str = "condition") -> DenseBasis:
    """All modes by dense ``eigh(K_r, M_r)`` (LAPACK ``sygvd``).

    The ``rigid`` lowest eigenvalues (the dimension of ``null K_r``, decided from the
    constraints by :mod:`.rigid`; ``None``: counted at round-off level behind a clear gap)
    are set to 0; the rest must be resolved (``guard``, see :func:`_resolved`).
    """
    lam, phi = sla.eigh(K.toarray(), M.toarray(), check_finite=False)
    if rigid is None:
        rigid = count_by_gap(lam, "dense eigen-solution")
    lam = _resolved(K, M, lam, phi, rigid, "dense eigen-solution", advice, None, guard)
    return DenseBasis(lam, phi, "dense", True)


def kronecker_basis(factors: KroneckerFactors, rigid: int | None,
                    advice: str = DEFAULT_ADVICE) -> DenseBasis:
    """All modes by the Kronecker reduction to standard form (:mod:`.kronecker_eigen`)."""
    lam, phi = kronecker_eigen.eigenpairs(factors)
    if rigid is None:
        rigid = count_by_gap(lam, "dense eigen-solution")
    return DenseBasis(check_resolved(lam, rigid, "dense eigen-solution", advice), phi,
                      "dense", True)


def separable_matrices(factors: KroneckerFactors) -> tuple[Array, Array, Array, Array]:
    """Reduced 1-D matrices ``(A_u, B_u, A_v, B_v)`` with ``K_r = A_u⊗B_v + B_u⊗A_v``, ``M_r = μ B_u⊗B_v``.

    ``A_u = w10 Ĝ^u_1 + w20 Ĝ^u_2``, ``A_v = w01 Ĝ^v_1 + w02 Ĝ^v_2``, ``B = Ĝ_0``.
    """
    w10, w01, w20, _, w02 = factors.weights
    gu, gv = factors.gram_u, factors.gram_v

    def tension_bending(g: tuple[Array, ...], w1: float, w2: float) -> Array:
        out = w1 * g[1]
        return out + w2 * g[2] if w2 else out

    return (tension_bending(gu, w10, w20), gu[0], tension_bending(gv, w01, w02), gv[0])


def separable_basis(factors: KroneckerFactors) -> SeparableBasis:
    """All modes from the two 1-D generalised eigenproblems ``A_u x = α B_u x``,
    ``A_v y = β B_v y`` (see :class:`~.bases.SeparableBasis`); needs ``w11 = 0``."""
    if not factors.separable:
        raise InputError("the separable eigensolver does not apply: the twist weight w11 is "
                         "not 0 (its term G1u⊗G1v couples the directions); use "
                         "eigensolver='dense' or 'sparse'")
    A_u, B_u, A_v, B_v = separable_matrices(factors)
    alpha, phi_u = sla.eigh(A_u, B_u, check_finite=False)
    beta, phi_v = sla.eigh(A_v, B_v, check_finite=False)
    alpha = check_resolved(alpha, factors.rigid_u, "separable eigen-solution in u",
                           DEFAULT_ADVICE)
    beta = check_resolved(beta, factors.rigid_v, "separable eigen-solution in v",
                          DEFAULT_ADVICE)
    return SeparableBasis(alpha, phi_u, beta, phi_v, factors.mass)


class OrderedFactor:
    """``A[order][:, order]`` factored without pivoting (symmetric positive definite
    ``A``); :meth:`solve` takes and returns vectors in the original order."""

    def __init__(self, A: sp.spmatrix, order: NDArray[np.int64]):
        self.order = order
        self.lu = spla.splu(sp.csc_matrix(A)[order][:, order].tocsc(), permc_spec="NATURAL",
                            diag_pivot_thresh=0.0, options={"SymmetricMode": True})

    def solve(self, b: Array) -> Array:
        out = np.empty_like(b, dtype=float)
        out[self.order] = self.lu.solve(np.asarray(b, dtype=float)[self.order])
        return out


def stiffness_factorisation(K: sp.spmatrix, shift: float = 0.0, M: sp.spmatrix | None = None,
                            order: NDArray[np.int64] | None = None) -> Any:
    """A factorisation of ``A = K - shift M`` with ``solve``.

    ``order``: a fill-reducing order of the unknowns known to the caller (e.g. a nested
    dissection of a tensor-product net), used as given without pivoting (the shell's
    path). Otherwise the band Cholesky (:func:`.factor.band_cholesky`) where the band fits
    and ``A`` is positive definite, else a sparse LU (minimum-degree ordering of
    ``Aᵀ + A``, threshold pivoting: a singular ``A`` raises).
    """
    A = K if shift == 0.0 else K - shift * M
    if order is None:
        band = band_cholesky(A)
        if band is not None:
            return band
    try:
        if order is not None:
            return OrderedFactor(A, order)
        return spla.splu(sp.csc_matrix(A), permc_spec="MMD_AT_PLUS_A")
    except RuntimeError:
        raise SingularSystemError(
            "the stiffness matrix is singular (some deformation costs no energy): constrain "
            "an edge or some control points, or add weights") from None


def _eigsh(K: sp.spmatrix, M: sp.spmatrix, k: int, shift: float, lu: Any) -> tuple[Array, Array]:
    n = K.shape[0]
    op = spla.LinearOperator((n, n), matvec=lu.solve, dtype=float)
    # a seeded start: ARPACK's own depends on the calls made before in the process
    v0 = np.random.default_rng(0).standard_normal(n)
    lam, phi = spla.eigsh(K, k=k, M=M, sigma=shift, which="LM", OPinv=op, v0=v0)
    order = np.argsort(lam)
    lam, phi = lam[order], phi[:, order]
    phi = phi / np.sqrt(np.einsum("ik,ik->k", phi, M @ phi))[None, :]
    return _zero_small(lam), phi


def sparse_basis(K: sp.spmatrix, M: sp.spmatrix, k: int | None = None,
                 omega_max: float | None = None, rigid: int | None = 0,
                 advice: str = DEFAULT_ADVICE, guard: str = "condition",
                 order: NDArray[np.int64] | None = None, mass_product: Any | None = None
                 ) -> DenseBasis:
    """Lowest modes by shift-invert Lanczos: without rigid modes and ``order`` the block
    Lanczos of :mod:`.sparse_eigen` on its factor of ``K`` (level-3 solves, one Krylov
    space for every request; ``mass_product``: its ``X ↦ M X``, e.g. through Kronecker
    factors), else ``eigsh`` with a sparse LU of ``K - σM``.

    ``k`` modes, or all with ``ω <= omega_max`` (found by doubling the request). One mode more
    than kept is computed so that the first omitted frequency is known. Without rigid modes
    (``rigid = 0``, the dimension of ``null K_r`` from :mod:`.rigid`) ``σ = 0`` and the LU of
    ``K`` is kept for the static part; with rigid modes (or ``None``, unknown: counted at
    round-off level behind a gap) ``K`` is singular, a small negative shift is used and
    there is no static solve. The ``rigid`` lowest eigenvalues are set to 0 and the rest
    checked against ``λ_max ≈ max K_ii/M_ii`` (``guard``, see :func:`_resolved`).
    ``order`` is passed to :func:`stiffness_factorisation`. Under ``guard="residual"`` the
    lowest vectors near refusal are refined first (:func:`.eigen_trust.refine_doubtful`).
    """
    n = K.shape[0]
    unconstrained = rigid != 0
    if unconstrained:
        scale = float(np.mean(K.diagonal() / M.diagonal()))
        shift = -1e-6 * scale
    else:
        shift = 0.0
    block = not unconstrained and order is None
    lu = factorise(K) if block else stiffness_factorisation(K, shift, M, order)
    solve = None if unconstrained else lu.solve
    krylov = BlockLanczos(K, M, lu, mass_product=mass_product) if block else None

    def pairs(count: int) -> tuple[Array, Array]:
        """The ``count`` lowest pairs (on one growing Krylov space with the block Lanczos)."""
        if krylov is None:
            return _eigsh(K, M, count, shift, lu)
        modes = krylov.lowest(count - 1)
        return _zero_small(modes.lam), modes.phi

    if omega_max is not None:
        want = min(32, n - 2)
        while True:
            lam, phi = pairs(want)
            if lam[-1] > omega_max**2 or want >= n - 2:
                break
            want = min(2 * want, n - 2)
        k = int(np.searchsorted(lam, omega_max**2, side="right"))
        if k == 0:
            raise InputError(f"no mode has ω <= omega_max = {omega_max:g} (lowest ω = "
                             f"{np.sqrt(lam[0]):g})")
    else:
        assert k is not None
        lam, phi = pairs(min(k + 1, n - 1))
    top = float(np.max(K.diagonal() / M.diagonal()))       # a Rayleigh quotient <= λ_max
    if rigid is None:
        rigid = count_by_gap(lam, "sparse eigen-solution", top)
    mass_solve = None
    if guard == "residual":         # the residuals judged: first rid them of the solves' rounding
        phi, mass_solve = refine_doubtful(K, M, lam, phi, min(rigid, lam.size), lu.solve)
    lam = _resolved(K, M, lam, phi, min(rigid, lam.size), "sparse eigen-solution", advice,
                    top, guard, mass_solve)
    first = lam[k] if k < lam.size else np.inf
    return DenseBasis(lam[:k], phi[:, :k], "sparse", k == n, solve, first)


def _dense_cost_note(n: int) -> str:
    return (f"all {n} modes of a general net need a dense eigen-decomposition "
            f"(O(n³) time, {8 * n * n / 2**30:.2g} GiB per matrix)")


def choose(n: int, eigensolver: str = "auto", truncated: bool = False,
           separable: bool = False) -> str:
    """The strategy for ``n`` free coordinates: ``dense``, ``separable`` or ``sparse``.

    ``auto``: dense ``eigh`` up to :data:`DENSE_LIMIT` free coordinates (the reference);
    above it the separable factors when they apply (``separable``); otherwise sparse
    Lanczos when only the lowest modes are wanted (``truncated``) and dense up to
    :data:`DENSE_MAX`.
    """
    if eigensolver not in EIGENSOLVERS:
        raise InputError(f"unknown eigensolver {eigensolver!r}; choose one of {EIGENSOLVERS}")
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
    if separable:
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
