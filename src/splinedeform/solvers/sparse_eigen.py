"""Lowest eigenpairs of ``K φ = λ M φ`` by block shift-invert Lanczos with one sparse LU.

The operator ``S = K⁻¹ M`` is self-adjoint in the M-inner product and its largest
eigenvalues ``ν = 1/λ`` are the lowest modes. From a random block ``X₀`` the Krylov space
``span{V₀, S V₀, S² V₀, …}`` is built ``b`` vectors at a time, M-orthonormal
(``Vᵀ M V = I``, classical Gram–Schmidt twice against every earlier block, a Cholesky QR
within the block), which leaves the Krylov relation

.. math:: S V = V H + W_{+} B E^{T},   \\qquad  H = Vᵀ M S V,

with ``W₊`` the next block and ``B`` its normalisation. A Ritz pair ``(ν, y = V s)`` of the
symmetric ``H`` then has the residual ``‖S y − ν y‖_M = ‖B s_{last}‖`` (the last ``b``
entries of ``s``) without touching an ``n``-vector, so convergence of the ``k + 1``
largest ``ν`` is checked cheaply; ``λ = 1/ν``, ``φ = V s``. A converged pair has
``|ν − ν_true| ≤ r²/gap`` and an eigenvector angle ``≤ r/gap`` (Kato–Temple, Davis–Kahan).

Why this and not ``scipy.sparse.linalg.eigsh``: ARPACK's implicitly restarted Lanczos does
the same number of solves with the same LU (``≈ 2k``) but orthogonalises one vector at a
time (level-2 BLAS) and re-runs its ``n × ncv`` work on every restart; measured on this
project's 2-core machine (one BLAS thread) at 64² (``n = 3969``, ``k = 257``) its own work
took 3–4 s of 4–5.7 s while the 516 solves took 1.2 s. Blocks make every ``n``-sized step
a matrix–matrix product, and SuperLU's multi-right-hand-side solve costs about half as much
per vector (1.2 ms against 2.3 ms at 64², 11 against 23 ms at 128²). ``lobpcg`` with the
Kronecker-separable part as preconditioner stalled at residuals of 1e-5 for 33 modes at 64²
(3.5 s) and needs a Rayleigh–Ritz of three blocks per step; a Kronecker-exact solve exists
only for ``w11 = 0`` (:class:`~.modal_basis.SeparableBasis`), so the general path keeps a
sparse LU, which also gives the static part of the omitted modes
(:mod:`.mode_acceleration`) for the price of one more solve per load term.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from numpy.typing import NDArray

from ..errors import SingularSystemError
from .block_cholesky import block_cholesky
from .factor import band_cholesky
from .products import gemm as _gemm

_gemv = sla.blas.dgemv

Array = NDArray[np.float64]
TOLERANCE = 1e-10
"""Relative residual ``‖S y − ν y‖_M / ν`` of an accepted Ritz pair."""
ROOM = 8
"""Basis vectors reserved per vector asked (:meth:`BlockLanczos._reserve`)."""


def factorise(K: sp.spmatrix) -> Any:
    """A factorisation of ``K`` with ``solve``: the block bidiagonal Cholesky
    (:func:`.block_cholesky.block_cholesky`, level-3 solves of a block of vectors) or the
    band Cholesky (:func:`.factor.band_cholesky`) where the band fits and ``K`` is positive
    definite, else the sparse LU (SuperLU, minimum-degree ordering of ``Kᵀ + K``, threshold pivoting,
    so that a singular ``K`` is reported rather than solved).

    The ordering matters for the LU: at 64² the ``MMD_AT_PLUS_A`` factors have 1.07 M
    entries and factorise in 0.09 s, ``COLAMD`` (scipy's default) 1.29 M in 0.35 s.
    """
    band = block_cholesky(K) or band_cholesky(K)
    if band is not None:
        return band
    try:
        return spla.splu(sp.csc_matrix(K), permc_spec="MMD_AT_PLUS_A")
    except RuntimeError:
        raise SingularSystemError(
            "the stiffness matrix is singular (some deformation costs no energy): constrain "
            "an edge or some control points, or add weights") from None


@dataclass
class LowestModes:
    """Result of :func:`lowest_modes`: ``Φ = V S`` kept as its two factors.

    Attributes
    ----------
    lam : (m,) ascending eigenvalues, ``m = k + 1`` unless all ``n`` modes were found.
    krylov : (n, p) the M-orthonormal Krylov basis ``V``.
    ritz : (p, m) the Ritz coordinates ``S`` (orthonormal columns), so ``Φᵀ M Φ = I``.
    residual : (m,) relative residuals ``‖S φ − ν φ‖_M / ν`` from the Krylov relation.
    solves : number of vectors solved with the LU.
    """

    lam: Array
    krylov: Array
    ritz: Array
    residual: Array
    solves: int

    @property
    def phi(self) -> Array:
        """All modes ``V S``, shape ``(n, m)``."""
        return self.columns(self.lam.size)

    def columns(self, m: int) -> Array:
        """The lowest ``m`` modes ``V S[:, :m]`` (only these are formed: ``O(n p m)``)."""
        return _gemm(1.0, self.krylov, self.ritz[:, :m])

    def project(self, F: Array) -> Array:
        """``Φᵀ F = Sᵀ (Vᵀ F)`` for ``F`` of shape ``(n, c)`` → ``(m, c)``."""
        return self.ritz.T @ _gemm(1.0, self.krylov, F, trans_a=1)

    def combine(self, Q: Array) -> Array:
        """``Φ[:, :r] Q = V (S[:, :r] Q)`` for ``Q`` of shape ``(r, c)``."""
        return _gemm(1.0, self.krylov, self.ritz[:, :Q.shape[0]] @ Q)


def _m_orthonormal(W: Array, MW: Array) -> tuple[Array, Array, Array]:
    """``(Q, MQ, R)`` with ``W = Q R``, ``Qᵀ M Q = I`` (Cholesky QR; rank-deficient columns
    are dropped by an eigen-decomposition of the Gram matrix instead)."""
    G = W.T @ MW
    G = 0.5 * (G + G.T)
    try:
        L = np.linalg.cholesky(G)
        if np.min(np.diag(L)) > 1e-7 * np.max(np.diag(L)):
            # Q = W L⁻ᵀ by a triangular solve from the right (dtrsm), in Fortran order: the
            # columns go into the column-major basis as they are
            Q = sla.blas.dtrsm(1.0, L, W, side=1, lower=1, trans_a=1)
            MQ = sla.blas.dtrsm(1.0, L, MW, side=1, lower=1, trans_a=1)
            return Q, MQ, L.T
    except np.linalg.LinAlgError:
        pass
    w, U = np.linalg.eigh(G)
    keep = w > 1e-14 * max(w.max(), 1e-300)
    scale = 1.0 / np.sqrt(w[keep])
    return (W @ U[:, keep]) * scale, (MW @ U[:, keep]) * scale, (U[:, keep] * np.sqrt(w[keep])).T


class BlockLanczos:
    """A block shift-invert Krylov space of ``S = K⁻¹M`` that grows on demand.

    :meth:`lowest` returns the ``k + 1`` lowest eigenpairs, extending the same space when a
    later call asks for more modes (nothing is recomputed).

    Parameters
    ----------
    K, M : sparse symmetric positive definite.
    lu : a factorisation of ``K`` with ``solve`` (:func:`factorise`), made if not given.
    block : block size ``b``; default :func:`block_size` of the modes asked for, widened
        (never narrowed) when a later call asks for more.
    tol : accepted relative residual of a Ritz pair.
    seed : of the random starting block.
    start : a starting block ``W₀ = K⁻¹F`` instead of a random one (a load's static
        response: the space of *load-dependent* Ritz vectors). Its block width is the rank
        of ``F`` and stays fixed. The space then holds only the modes the load excites, so
        it may serve that load alone: a mode with ``φᵀF = 0`` is never found, and another
        load may need it.
    mass_product : ``X ↦ M X`` by another route than the sparse ``M`` (the factors of a
        Kronecker product, :mod:`.kronecker_product`), for the one product per vector.
    """

    def __init__(self, K: sp.spmatrix, M: sp.spmatrix, lu: Any | None = None,
                 block: int | None = None, tol: float = TOLERANCE, seed: int = 0,
                 start: Array | None = None, mass_product: Any | None = None):
        self.K, self.M = K, M
        self.mass = mass_product or M.__matmul__
        self.n = K.shape[0]
        self.lu = factorise(K) if lu is None else lu
        self.tol = tol
        self.fixed = block is not None or start is not None
        self.wide = getattr(self.lu, "method", "") == "block"   # level-3 solves: wider blocks
        self.b = min(block or block_size(1, self.wide), self.n)
        self.rng = np.random.default_rng(seed)
        self.V = np.empty((self.n, 0))
        self.MV = np.empty((self.n, 0))
        self.H = np.zeros((0, 0))
        self.p = self.lo = 0
        self.solves = 0
        self.next: tuple[Array, Array, Array] | None = None    # (Q, MQ, B) of the next block
        if start is None:
            X = self.rng.standard_normal((self.n, self.b))
            W = self.lu.solve(self.mass(X))
            self.solves += self.b
        else:
            W = np.asarray(start, dtype=float).reshape(self.n, -1)
        Q, MQ, _ = _m_orthonormal(W, self.mass(W))
        if start is not None:
            if Q.shape[1] == 0:
                raise ValueError("the starting block of a load-started Krylov space is zero")
            self.b = Q.shape[1]
        self._append(Q, MQ)

    def _reserve(self, size: int) -> None:
        """Room for ``size`` basis vectors: :data:`ROOM` times ``size`` and at least twice
        the room before (twice ``size`` where that much address space is refused; the
        starting block alone gets no more than its own room, :meth:`lowest` knowing the
        mode count). Column-major: the vectors in use are one contiguous prefix, and the
        memory of the columns not yet written is never touched, so the room costs address
        space, not memory, while a copy into a larger room touches the memory of every
        vector again (at 128² a copy of 688 columns of ``V`` and ``MV`` cost 0.36 s of
        processor time when the mode count grew from 256 to 322). The automatic mode count
        (:func:`.mode_select.automatic_basis`) asks 17, 65, then 154 pairs on the bench
        plate at 128²: with twice the room its space was copied at 144 and 288 vectors,
        with eight times not at all (920 vectors reserved, 464 used)."""
        if size <= self.V.shape[1]:
            return
        wanted = ROOM * size if self.p else size
        for room in (max(wanted, 2 * self.V.shape[1]), 2 * size):
            room = min(self.n, room)
            try:
                V, MV = (np.empty((self.n, room), order="F") for _ in range(2))
                H = np.zeros((room, room))
                break
            except MemoryError:
                if room <= min(self.n, 2 * size):
                    raise
        V[:, :self.p] = self.V[:, :self.p]
        MV[:, :self.p] = self.MV[:, :self.p]
        H[:self.p, :self.p] = self.H[:self.p, :self.p]
        self.V, self.MV, self.H = V, MV, H

    def _append(self, Q: Array, MQ: Array) -> None:
        grow = min(Q.shape[1], self.n - self.p)
        self._reserve(self.p + grow)
        self.V[:, self.p:self.p + grow] = Q[:, :grow]
        self.MV[:, self.p:self.p + grow] = MQ[:, :grow]
        self.lo, self.p = self.p, self.p + grow

    def _step(self) -> None:
        """Apply ``S`` to the last block, orthogonalise, fill ``H``'s columns.

        ``S = K⁻¹M`` is self-adjoint in the M inner product, so ``S V_j`` is M-orthogonal to
        every block but the last two in exact arithmetic: the first Gram–Schmidt pass is
        against those (the block three-term recurrence), the second against the whole basis
        (full re-orthogonalisation, which removes what rounding left), half the work of two
        full passes. The coefficients of both passes add up in ``H``.
        """
        p, lo = self.p, self.lo
        if p - lo == 1:
            return self._step_vector()
        V, MV = self.V[:, :p], self.MV[:, :p]
        W = np.asfortranarray(self.lu.solve(self.MV[:, lo:p]))
        self.solves += p - lo
        near = max(0, lo - (p - lo))            # the last two blocks
        C = _gemm(1.0, MV[:, near:], W, trans_a=1)
        W = _gemm(-1.0, V[:, near:], C, 1.0, W)
        C2 = _gemm(1.0, MV, W, trans_a=1)
        W = _gemm(-1.0, V, C2, 1.0, W)
        C2[near:] += C
        self.H[:p, lo:p] = C2
        self.next = _m_orthonormal(W, self.mass(W))

    def _step_vector(self) -> None:
        """:meth:`_step` for a block of one vector (a space started from one load
        direction): ``w = S v_p``, Gram–Schmidt against the last two vectors (the
        three-term recurrence) and then against the whole basis, ``w ← w − V (MVᵀ w)``
        (two matrix–vector products, level-2 BLAS on the column-major basis), as the
        block step does, and the next vector ``w / ‖w‖_M`` with ``B = ‖w‖_M``. It spares
        the block step's Gram matrix, its Cholesky factor and the two triangular solves of
        the normalisation, which at 64² took about as long as the orthogonalisation."""
        p = self.p
        V, MV = self.V[:, :p], self.MV[:, :p]
        w = np.asarray(self.lu.solve(self.MV[:, p - 1]), dtype=float).ravel()
        self.solves += 1
        near = max(0, p - 2)                    # the last two vectors
        c = _gemv(1.0, MV[:, near:], w, trans=1)
        w = _gemv(-1.0, V[:, near:], c, 1.0, w, overwrite_y=1)
        c2 = _gemv(1.0, MV, w, trans=1)
        w = _gemv(-1.0, V, c2, 1.0, w, overwrite_y=1)
        c2[near:] += c
        self.H[:p, p - 1] = c2
        Mw = np.asarray(self.mass(w)).ravel()
        norm2 = float(w @ Mw)
        if not norm2 > 0.0 or not np.isfinite(norm2):      # an invariant subspace
            self.next = (np.empty((self.n, 0)), np.empty((self.n, 0)), np.empty((0, 1)))
            return
        b = np.sqrt(norm2)
        self.next = ((w / b)[:, None], (Mw / b)[:, None], np.array([[b]]))

    def _advance(self) -> None:
        assert self.next is not None
        Q, MQ, _ = self.next
        width = max(self.p - self.lo, self.b)
        if Q.shape[1] < width:              # an invariant subspace, or a wider block: fresh
            # directions (their rows of B are 0, so the residual formula still holds)
            extra = self.rng.standard_normal((self.n, width - Q.shape[1]))
            extra -= self.V[:, :self.p] @ (self.MV[:, :self.p].T @ extra)
            extra -= Q @ (MQ.T @ extra)
            E, ME, _ = _m_orthonormal(extra, self.mass(extra))
            Q, MQ = np.hstack([Q, E]), np.hstack([MQ, ME])
        self.next = None
        self._append(Q, MQ)

    def _ritz(self, want: int) -> tuple[Array, Array, Array]:
        """Ritz values ``ν`` (descending), vectors ``s`` and relative residuals."""
        p, lo = self.p, self.lo
        # the coefficients fill H's upper triangle (its columns): eigh reads that one
        nu, S = np.linalg.eigh(self.H[:p, :p], UPLO="U")
        nu, S = nu[::-1], S[:, ::-1]
        assert self.next is not None
        Q, _, B = self.next
        # S V = V H + Q B E_lastᵀ: the residual of y = V s is Q B s_last, M-norm ‖B s_last‖
        res = np.linalg.norm(B @ S[lo:p, :want], axis=0) if Q.shape[1] else np.zeros(want)
        return nu, S, res / np.maximum(np.abs(nu[:want]), 1e-300)

    def lowest(self, k: int, max_dim: int | None = None) -> LowestModes:
        """The ``k + 1`` lowest eigenpairs (all ``n`` if the space fills ``R^n``).

        ``max_dim`` caps the Krylov dimension (default ``min(n, 6(k + 1) + 4b)``); pairs
        not converged by then are returned with their residuals.
        """
        want = min(k + 1, self.n)
        if not self.fixed:
            self.b = max(self.b, min(block_size(want, self.wide), self.n))
        cap = min(self.n, max_dim or 6 * want + 4 * self.b)
        self._reserve(min(cap, 3 * want + 4 * self.b))     # what it usually takes: no copies
        check = max(min(2 * want, cap), self.p)
        while True:
            if self.next is None:
                self._step()
            if self.p >= check or self.p >= self.n or self.p >= cap:
                check = max(self.p + 1, int(1.08 * self.p))
                nu, S, rel = self._ritz(min(want, self.p))
                if self.p >= self.n or self.p >= cap or (self.p >= want
                                                           and np.all(rel <= self.tol)):
                    m = self.p if self.p >= self.n else min(want, self.p)
                    return LowestModes(1.0 / nu[:m], self.V[:, :self.p], S[:, :m],
                                       rel[:m], self.solves)
            self._advance()


def block_size(want: int, wide: bool = False) -> int:
    """Block size for ``want`` eigenpairs: ``clip(want/2, 2, 8)``; 16 when ``wide`` (the
    factor solves a block of vectors with level-3 BLAS, :mod:`.block_cholesky`).

    Measured at 64² (solves to reach residuals of 1e-10 with blocks of 1, 2, 4, 8): 17
    pairs 55, 56, 76, 104; 33 pairs 83, 92, 120, 160; 257 pairs with 8, 16, 32: 592, 688,
    864 (ARPACK 516). Narrow blocks need fewest solves; wide ones read the Krylov basis
    fewer times in the orthogonalisation, which dominates from a few dozen pairs on with
    one BLAS thread: 291 pairs at 64² took 2.9 s with blocks of 2, 0.88 s with 8, 1.3 s
    with 16; 17, then 65, then 312 pairs on the same space 1.5 s growing the block from 2,
    1.1 s with 8 from the start. At 128² (band solve 8.1 ms a vector, block sweeps 2.2 ms
    in blocks of 16) 200 pairs took 472 solves with blocks of 8 and 576 with 16.
    """
    if wide:
        return 16
    return int(np.clip(want // 2, 2, 8))


def lowest_modes(K: sp.spmatrix, M: sp.spmatrix, k: int, lu: Any | None = None,
                 block: int | None = None, tol: float = TOLERANCE, seed: int = 0,
                 max_dim: int | None = None) -> LowestModes:
    """The ``k + 1`` lowest eigenpairs (one more than asked, so that the first omitted
    eigenvalue is known) by block shift-invert Lanczos (:class:`BlockLanczos`)."""
    return BlockLanczos(K, M, lu, block, tol, seed).lowest(k, max_dim)
