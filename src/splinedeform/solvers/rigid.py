"""Rigid-body modes decided from the constraints, and whether an eigen-solution can be trusted.

A rigid mode is a motion without strain energy, ``K_r φ = 0``. Its eigenvalue is 0 exactly;
an eigensolver returns it as round-off of size ``ε λ_max``, which a relative cut cannot tell
from a real but soft mode (a plate of many cells, a tiny weight). So the number of rigid
modes is taken from the structure, never from the eigenvalues:

* per direction the polynomial spaces ``U_0 = span{1} ⊂ U_1 = span{1, x}`` (those the
  basis reproduces; a periodic basis has no ``x``) form a chain. ``G_1`` vanishes exactly on
  ``U_0``, ``G_2`` on ``U_1``, ``G_0`` nowhere. So a term ``w G_a ⊗ G_b`` of ``K`` vanishes
  on ``U_{a-1} ⊗ R + R ⊗ V_{b-1}`` (``U_{-1} = 0``), and with ``U_2 = R^n`` the null space
  of ``K`` is ``Σ U_k ⊗ V_l`` over the cells ``(k, l) ∈ {0,1,2}²`` with ``k < a`` or ``l < b``
  for every term of non-zero weight;
* the constraints keep ``range T``. For per-edge constraints ``T = T_u ⊗ T_v`` a chain and one
  subspace share an adapted basis, so ``null K_r`` has dimension
  ``Σ_{allowed (k,l)} e_u(k) e_v(l)`` with ``e(k) = dim(U_k ∩ range T_1d) − dim(U_{k−1} ∩ range T_1d)``,
  each a rank of a small, well-scaled polynomial matrix;
* for other constraints (a mask of fixed points, poles) the basis ``Z`` of ``null K`` is formed
  and ``dim(range Z ∩ range T) = p − rank(T Z[free] − Z)`` (the rows ``free`` of ``T`` are
  the identity).

The intrinsic plate under tension ``T > 0`` vanishes only on constants. Where no structure
is known (the intrinsic plate without tension), :func:`count_by_gap` counts eigenvalues
at round-off level and refuses unless a clear gap separates them from the rest.

Where the structure leaves the count open (a bending body with a free part, whose energy
vanishes on fields that depend on its geometry), :func:`null_space` finds ``null K_r`` on the
matrices: dense ``eigh`` of a small system, block shift-invert Lanczos near 0 of a large one.

Trust: a backward-stable eigensolver resolves each eigenvalue to about ``ε λ_max``
(LAPACK's backward error), so the lowest elastic eigenvalue ``λ_e`` has relative accuracy
about ``ε κ`` with ``κ = λ_max/λ_e``. :func:`check_resolved` refuses when that exceeds
:data:`TRUST`, naming ``κ`` and what to change.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from numpy.typing import NDArray

from ..errors import SingularSystemError
from .sparse_eigen import lowest_modes

Array = NDArray[np.float64]
EPS = float(np.finfo(float).eps)
TRUST = 1e-4
"""Largest accepted relative error estimate ``ε λ_max/λ_e`` of the lowest elastic eigenvalue."""
ROUNDOFF = 1e-6
"""A rigid mode's computed ``|λ|`` above ``ROUNDOFF · λ_max`` contradicts the structure."""
DENSE_NULL = 1500
"""Most unknowns whose null space :func:`null_space` finds by dense ``eigh`` (a few
seconds); larger systems take shift-invert Lanczos near 0."""
SHIFT = 1e-12
"""The shift ``σ = SHIFT · λ_max`` of :func:`null_space`'s Lanczos: well below every
eigenvalue that :func:`count_by_gap` accepts as elastic (``1e8 ε λ_max ≈ 2e-8 λ_max``),
well above the round-off of ``K``'s null eigenvalues (``1e3 ε λ_max ≈ 2e-13 λ_max``), so
that ``K + σ M`` is positive definite."""


def polynomial_chain(basis: Any) -> list[Array]:
    """Coefficients of ``1`` and ``x`` in a 1-D basis, ``[Z_0 (n,1), Z_1 (n,2)]``.

    Candidates are the partition of unity ``(1, …, 1)`` and the Greville abscissae (exact
    for B-splines), checked on sample points; where a candidate fails (a rational basis)
    least squares decides. ``x`` is dropped when the basis does not reproduce it (periodic
    knots), so ``Z_1 = Z_0`` there. ``x`` is centred and scaled to ``[-1, 1]`` so that both
    columns are of unit size.
    """
    lo, hi = getattr(basis, "domain", (0.0, getattr(basis, "length", 1.0)))
    x = np.linspace(lo, hi, 2 * basis.size + 7)
    B = basis.matrix(x)
    targets = np.column_stack([np.ones_like(x), (2.0 * x - (lo + hi)) / (hi - lo)])
    coef = np.column_stack([np.ones(basis.size), np.zeros(basis.size)])
    if hasattr(basis, "greville"):
        coef[:, 1] = (2.0 * np.asarray(basis.greville(), dtype=float) - (lo + hi)) / (hi - lo)
    fit = np.abs(B @ coef - targets).max(axis=0)
    if np.any(fit >= 1e-10) and not getattr(basis, "periodic", False):
        coef, *_ = np.linalg.lstsq(np.asarray(B.toarray()), targets, rcond=None)
        fit = np.abs(B @ coef - targets).max(axis=0)
    keep = fit < 1e-8
    z0 = coef[:, :1] if keep[0] else np.zeros((basis.size, 0))
    return [z0, coef[:, keep]]


def _rank(D: Array, scale: float) -> int:
    if D.size == 0:
        return 0
    s = np.linalg.svd(D, compute_uv=False)
    return int(np.sum(s > 1e-9 * max(scale, 1.0) * np.sqrt(D.shape[0])))


def _kept_dimensions(chain: list[Array], T: sp.spmatrix) -> list[int]:
    """``dim(U_k ∩ range T)`` for ``k = 0, 1`` and ``range T`` itself (``k = 2``)."""
    Td = np.asarray(T.toarray())
    Q, _ = np.linalg.qr(Td)                       # T has full column rank
    dims = []
    for Z in chain:
        D = Z - Q @ (Q.T @ Z)                     # the part of U_k outside range T
        dims.append(Z.shape[1] - _rank(D, np.abs(Z).max(initial=1.0)))
    return dims + [T.shape[1]]


def _allowed(terms: list[tuple[int, int]]) -> list[tuple[int, int]]:
    """Cells ``(k, l)`` of the null space: ``k < a`` or ``l < b`` for every term ``(a, b)``."""
    return [(k, l) for k in range(3) for l in range(3)
            if all(k < a or l < b for a, b in terms)]


def parametric_terms(material: Any) -> list[tuple[int, int]]:
    """Derivative orders ``(a, b)`` of the terms ``G_a ⊗ G_b`` of ``K`` with non-zero weight."""
    m = material
    pairs = [(m.w10, (1, 0)), (m.w01, (0, 1)), (m.w20, (2, 0)), (m.w11, (1, 1)),
             (m.w02, (0, 2))]
    return [ab for w, ab in pairs if w]


def rigid_count(terms: list[tuple[int, int]] | None, basis_u: Any, basis_v: Any,
                constraints: Any) -> int | None:
    """Dimension of ``null K_r`` from the stiffness terms and the constraints.

    ``terms`` are the derivative orders ``(a, b)`` of the terms ``G_a ⊗ G_b`` of ``K`` with
    non-zero weight (:func:`parametric_terms`; ``[(1, 0), (0, 1)]`` for the intrinsic plate
    under tension, whose energy vanishes on constants only); ``None`` where no structure is
    known (the intrinsic plate without tension, whose energy vanishes on discrete harmonic
    fields): then the count is ``None``. ``constraints`` has ``T``, ``free_index`` and, for
    per-edge constraints, ``T_u`` and ``T_v``. See the module docstring.
    """
    if terms is None:
        return None
    c = constraints
    cells = _allowed(terms)
    if not cells:
        return 0
    chain_u = polynomial_chain(basis_u)
    chain_v = polynomial_chain(basis_v)
    if c.T_u is not None and c.T_v is not None:
        du, dv = _kept_dimensions(chain_u, c.T_u), _kept_dimensions(chain_v, c.T_v)
        eu = np.diff([0] + du)
        ev = np.diff([0] + dv)
        return int(sum(eu[k] * ev[l] for k, l in cells))
    return _general_count(chain_u, chain_v, cells, c)


def _general_count(chain_u: list[Array], chain_v: list[Array], cells: list[tuple[int, int]],
                   c: Any) -> int:
    """``p − rank(T Z[free] − Z)`` for the basis ``Z`` of ``null K`` (any constraint map)."""
    def levels(chain: list[Array]) -> list[Array]:
        n = chain[0].shape[0]
        Q, _ = np.linalg.qr(np.column_stack([chain[1], np.eye(n)]))
        n0, n1 = chain[0].shape[1], chain[1].shape[1]
        return [Q[:, :n0], Q[:, n0:n1], Q[:, n1:n]]

    lu, lv = levels(chain_u), levels(chain_v)
    blocks = [np.kron(lu[k], lv[l]) for k, l in cells if lu[k].shape[1] and lv[l].shape[1]]
    if not blocks:
        return 0
    Z = np.column_stack(blocks)
    T = c.T
    if abs(T[c.free_index] - sp.identity(T.shape[1])).max() != 0:
        raise AssertionError("the constraint map is not the identity on its free points")
    D = np.asarray(T @ Z[c.free_index]) - Z
    return Z.shape[1] - _rank(D, 1.0)


class UnresolvedSpectrum(SingularSystemError):
    """The eigensolver cannot resolve the lowest elastic modes of this problem."""


def direction_rigid(basis: Any, T: sp.spmatrix, orders: list[int]) -> int:
    """``dim null(Tᵀ Σ_a w_a G_a T)`` in one direction, ``orders`` the ``a`` with ``w_a ≠ 0``."""
    dims = _kept_dimensions(polynomial_chain(basis), T)
    e = np.diff([0] + dims)
    return int(sum(e[k] for k in range(3) if all(k < a for a in orders)))


def count_by_gap(lam: Array, what: str, top: float | None = None) -> int:
    """Eigenvalues at round-off level (``<= 1e3 ε λ_max``), refused without a clear gap.

    A gap means the next eigenvalue is at least ``1e8 ε λ_max`` (so resolved to 1e-8
    relative at worst, 5 decades above the round-off level). ``top`` is ``λ_max`` (or an
    estimate) when ``lam`` holds only the lowest eigenvalues.
    """
    lam = np.sort(np.asarray(lam, dtype=float))
    top = float(np.abs(lam).max(initial=0.0)) if top is None else float(top)
    zero = lam <= 1e3 * EPS * top
    grey = (~zero) & (lam < 1e8 * EPS * top)
    if np.any(grey):
        raise UnresolvedSpectrum(
            f"{what}: eigenvalues between {lam[grey].min():.3g} and {lam[grey].max():.3g} "
            f"lie {top / lam[grey].min():.3g} times below the largest ({top:.3g}), too close "
            "to round-off to tell rigid from soft modes. Constrain an edge, add tension "
            "(w10 = w01 > 0), or use fewer cells")
    return int(zero.sum())


def check_resolved(lam: Array, rigid: int, what: str, advice: str, top: float | None = None
                   ) -> Array:
    """Eigenvalues (ascending) with the ``rigid`` lowest set to 0, refused if unresolved.

    ``top`` is ``λ_max`` (or an estimate) when ``lam`` holds only the lowest eigenvalues.

    Raises
    ------
    SingularSystemError
        When ``ε λ_max / λ_e`` exceeds :data:`TRUST` for the lowest elastic ``λ_e`` (the
        eigensolver cannot resolve it; the message gives ``κ = λ_max/λ_e`` and ``advice``),
        or when a structurally rigid mode has ``|λ| > ROUNDOFF λ_max``.
    """
    lam = np.array(lam, dtype=float)
    if rigid >= lam.size:
        return np.zeros_like(lam)
    top = float(np.abs(lam).max()) if top is None else float(top)
    if rigid and np.abs(lam[:rigid]).max() > ROUNDOFF * top:
        raise UnresolvedSpectrum(
            f"{what}: the constraints leave {rigid} rigid mode(s) but the eigensolver found "
            f"eigenvalue {np.abs(lam[:rigid]).max():.3g} among them (largest {top:.3g}); the "
            "eigen-solution is not trustworthy. Use fewer cells or a lower degree")
    lam[:rigid] = 0.0
    if rigid < lam.size and top > 0:
        low = float(lam[rigid])
        kappa = top / low if low > 0 else np.inf
        if EPS * kappa > TRUST:
            raise UnresolvedSpectrum(
                f"{what}: the lowest elastic eigenvalue {low:.3g} is {kappa:.3g} times below "
                f"the largest ({top:.3g}); an eigensolver resolves it only to about "
                f"{min(EPS * kappa, 1.0):.1g} of itself (condition number {kappa:.3g}). "
                f"{advice}")
    return lam


def null_space(K: sp.spmatrix, M: sp.spmatrix, what: str, known: Array | None = None
               ) -> Array:
    """An M-orthonormal basis ``Z`` (``Zᵀ M Z = I``) of ``null K`` for ``K`` symmetric
    positive semi-definite and ``M`` positive definite: the eigenvectors of
    ``K φ = λ M φ`` at round-off level, ``λ <= 1e3 ε λ_max``.

    Up to :data:`DENSE_NULL` unknowns by dense ``eigh``. Beyond, the lowest pairs of the
    shifted pencil ``(K + σ M) φ = (λ + σ) M φ`` (positive definite) by block shift-invert
    Lanczos (:func:`.sparse_eigen.lowest_modes`), ``σ = SHIFT λ_max``: the null space's
    ``ν = 1/σ`` lie a factor ``≥ 2e4`` above every elastic ``ν = 1/(λ + σ)`` that
    :func:`count_by_gap` accepts, so the Krylov space finds it in a few blocks. A block
    Krylov space holds at most ``b`` independent eigenvectors of one eigenvalue, so ``b``
    pairs are asked with blocks of ``b = 8``, then 16, … until fewer than ``b`` are
    round-off. ``λ_max`` is estimated by ARPACK to 1e-2 (the thresholds of
    :func:`count_by_gap` are decades apart).

    Stiff penalties (a crease's rotation penalty) push ``λ_max`` so far up that the lowest
    elastic eigenvalues fall below the clear gap of :func:`count_by_gap` while still
    decades above round-off. ``known`` (``(n, c)``, motions known to cost no energy where
    they are admissible: translations, rotations) then decides: the round-off eigenvalues
    are accepted when the known motions explain every one of them, i.e. when as many
    independent combinations ``Y a`` of them have ``aᵀ Yᵀ K Y a <= 1e3 ε λ_max aᵀ Yᵀ M Y a``
    (the small pencil ``(Yᵀ K Y, Yᵀ M Y)``), and those combinations are the basis
    returned (exact, where an eigenvector so close to the elastic ones is not); with no
    eigenvalue at round-off level and none of the known motions admissible the null space
    is ``{0}``.

    Raises
    ------
    UnresolvedSpectrum
        When no clear gap separates round-off from the elastic eigenvalues and the known
        motions do not explain the round-off ones.
    """
    n = K.shape[0]
    if n <= DENSE_NULL:
        lam, phi = sla.eigh(K.toarray(), M.toarray(), check_finite=False)
        count, Z = _rigid_count(lam, float(np.abs(lam).max(initial=0.0)), K, M, known, what)
        return phi[:, :count] if Z is None else Z
    try:
        top = float(spla.eigsh(K, k=1, M=sp.csc_matrix(M), which="LA", tol=1e-2,
                               return_eigenvectors=False)[0])
    except spla.ArpackNoConvergence as exc:
        if not len(exc.eigenvalues):
            raise UnresolvedSpectrum(f"{what}: ARPACK found no estimate of the largest "
                                     "eigenvalue") from None
        top = float(np.max(exc.eigenvalues))
    sigma = SHIFT * top
    shifted = (K + sigma * M).tocsc()
    block = 8
    while True:
        found = lowest_modes(shifted, M, block - 1, block=block)
        count, Z = _rigid_count(found.lam - sigma, top, K, M, known, what)
        if count < block or block >= n:
            return found.columns(count) if Z is None else Z
        block *= 2


def _rigid_count(lam: Array, top: float, K: sp.spmatrix, M: sp.spmatrix,
                 known: Array | None, what: str) -> tuple[int, Array | None]:
    """:func:`count_by_gap` (and no basis: the eigenvectors are one), or where it finds no
    clear gap the round-off eigenvalues that the ``known`` motions explain, with the
    M-orthonormal basis of the combinations of them that ``K`` annihilates
    (:func:`null_space`)."""
    try:
        return count_by_gap(lam, what, top), None
    except UnresolvedSpectrum:
        if known is None:
            raise
        zero = int(np.sum(lam <= 1e3 * EPS * top))
        Y = np.asarray(known, dtype=float)
        w, V = np.linalg.eigh(Y.T @ np.asarray(M @ Y))
        keep = w > 1e-12 * w.max(initial=0.0)          # independent motions only
        Y = Y @ (V[:, keep] / np.sqrt(w[keep]))          # M-orthonormal: Yᵀ M Y = I
        low, A = np.linalg.eigh(Y.T @ np.asarray(K @ Y))
        explained = low <= 1e3 * EPS * top
        if int(explained.sum()) != zero:
            raise
        return zero, Y @ A[:, explained]
