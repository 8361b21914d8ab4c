"""Whether computed eigenpairs can be trusted, judged by their residuals.

:func:`.rigid.check_resolved` estimates the error of the lowest elastic eigenvalue from the
condition number ``κ = λ_max/λ_e`` (a backward-stable solver's worst case ``ε κ``). That
worst case is often far from the truth: a net whose largest eigenvalues come from a few
small cells (near a pole) resolves its low modes well. This module tests the computed pairs
themselves. For ``K φ = λ M φ`` symmetric with ``M`` positive definite and ``φᵀ M φ = 1``,
the residual ``r = K φ − λ M φ`` bounds the errors (Parlett, *The Symmetric Eigenvalue
Problem*, §15):

* some eigenvalue lies within ``η = ‖r‖_{M⁻¹} = √(rᵀ M⁻¹ r)`` of ``λ``;
* the angle (in the ``M`` inner product) between ``φ`` and the eigenspace of its cluster
  is at most ``η / gap``, ``gap`` the distance from ``λ`` to the nearest computed
  eigenvalue outside the cluster (Davis–Kahan). A cluster gathers eigenvalues within
  ``TRUST`` of each other: mixing their vectors changes ``K Φ`` no more than the
  frequencies' own tolerance.

The residual is evaluated in floating point, so its own round-off (``ε |K| |φ|``, the
condition number's fear) is part of what is measured. The norm ``‖r‖_{M⁻¹}`` takes one
Cholesky factorisation of the positive definite ``M`` (:func:`.factor.factorise`: the band
Cholesky where the tensor-product net's Kronecker order keeps ``M`` banded).
"""

from __future__ import annotations

from typing import Any

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray

from .factor import factorise
from .rigid import ROUNDOFF, TRUST, UnresolvedSpectrum

Array = NDArray[np.float64]
SHAPE_TRUST = 1e-3
"""Largest accepted angle bound ``η/gap`` (radians) of a mode shape or of its cluster."""
CHECKED = 32
"""How many of the lowest elastic modes are tested (the higher ones are relatively better)."""
GUARDS = ("condition", "residual", "off")
DOUBT = 10.0
"""Pairs whose bounds come within this factor of refusal are refined before the check."""


def residual_bounds(K: sp.spmatrix, M: sp.spmatrix, lam: Array, phi: Array,
                    mass_solve: Any | None = None) -> tuple[Array, Array]:
    """Per pair, the eigenvalue bound ``η_i`` and the angle bound ``η_i / gap_i``.

    ``phi`` is rescaled to ``φᵀ M φ = 1`` first. Neighbours closer than ``TRUST λ`` or than
    ``η_i + η_j`` form a cluster, whose eigenspace (not each vector) is what the bound
    concerns; ``gap_i`` is the distance to the nearest computed eigenvalue outside the
    cluster (the last pair has no computed neighbour above it, so its gap is the one below).
    """
    Mphi = M @ phi
    phi = phi / np.sqrt(np.einsum("ik,ik->k", phi, Mphi))[None, :]
    r = K @ phi - (M @ phi) * lam[None, :]
    mass_solve = mass_solve or factorise(M).solve
    eta = np.sqrt(np.maximum(np.einsum("ik,ik->k", r, mass_solve(r)), 0.0))
    order = np.argsort(lam)
    ls, es = lam[order], eta[order]
    # a cluster: neighbours closer than TRUST of ω² (mixing them changes K Φ by no more
    # than the frequencies' own tolerance) or than their error bounds
    split = np.diff(ls) > TRUST * np.abs(ls[1:]) + es[1:] + es[:-1]
    cluster = np.empty_like(order)
    cluster[order] = np.concatenate([[0], np.cumsum(split)])
    distance = np.abs(lam[:, None] - lam[None, :])
    gap = np.where(cluster[:, None] != cluster[None, :], distance, np.inf).min(axis=1)
    return eta, eta / gap


def check_by_residual(K: sp.spmatrix, M: sp.spmatrix, lam: Array, phi: Array, rigid: int,
                      what: str, advice: str, top: float | None = None,
                      guard: str = "residual", mass_solve: Any | None = None) -> Array:
    """Eigenvalues (ascending) with the ``rigid`` lowest set to 0, refused if unresolved.

    ``guard``: ``"residual"`` tests the lowest :data:`CHECKED` elastic pairs by their
    residuals (module docstring): refused when ``η/λ > TRUST`` or ``η/gap > SHAPE_TRUST``;
    ``"off"`` trusts them (at the caller's risk). A structurally rigid mode with
    ``|λ| > ROUNDOFF λ_max`` is refused under both, unless ``"off"``. ``mass_solve``:
    ``M⁻¹`` if the caller has it factorised.
    """
    if guard not in ("residual", "off"):
        raise ValueError(f"guard must be 'residual' or 'off', got {guard!r}")
    lam = np.array(lam, dtype=float)
    if rigid >= lam.size:
        return np.zeros_like(lam)
    top = float(np.abs(lam).max()) if top is None else float(top)
    if guard == "off":
        lam[:rigid] = 0.0
        return lam
    if rigid and np.abs(lam[:rigid]).max() > ROUNDOFF * top:
        raise UnresolvedSpectrum(
            f"{what}: the constraints leave {rigid} rigid mode(s) but the eigensolver found "
            f"eigenvalue {np.abs(lam[:rigid]).max():.3g} among them (largest {top:.3g}); the "
            f"eigen-solution is not trustworthy. {advice}")
    lam[:rigid] = 0.0
    pick = slice(rigid, min(lam.size, rigid + CHECKED))
    eta, angle = residual_bounds(K, M, lam[pick], np.asarray(phi)[:, pick], mass_solve)
    relative = eta / np.maximum(lam[pick], 1e-300)
    bad = np.flatnonzero((relative > TRUST) | (angle > SHAPE_TRUST))
    if bad.size:
        i = int(bad[0])
        known = (f"its frequency is known only to {relative[i] / 2:.1g} of itself"
                 if relative[i] < 1 else "its frequency is not resolved at all (the bound "
                 "exceeds ω²)")
        if 0 < angle[i] < np.inf:
            known += f", its shape to an angle of {min(angle[i], np.pi / 2):.1g} rad"
        raise UnresolvedSpectrum(
            f"{what}: mode {rigid + i + 1} (ω² = {lam[rigid + i]:.6g}) has the residual "
            f"‖Kφ − ω²Mφ‖ = {eta[i]:.2g} (in the M⁻¹ norm): {known}. {advice}")
    return lam



def _extended_product(A: sp.csr_matrix, X: Array) -> NDArray[np.longdouble]:
    """``A X`` summed in extended precision (``np.longdouble``), ``X`` of shape ``(n, c)``."""
    terms = A.data.astype(np.longdouble)[:, None] * X.astype(np.longdouble)[A.indices]
    out = np.zeros((A.shape[0], X.shape[1]), dtype=np.longdouble)
    rows = np.flatnonzero(np.diff(A.indptr))
    out[rows] = np.add.reduceat(terms, A.indptr[rows], axis=0)
    return out


def refine_doubtful(K: sp.spmatrix, M: sp.spmatrix, lam: Array, phi: Array, rigid: int,
                    solve: Any) -> tuple[Array, Any]:
    """``phi`` with those of its checked pairs refined (:func:`refine_pairs`) whose bounds
    come within a factor :data:`DOUBT` of refusal (``η/λ > TRUST/DOUBT`` or
    ``η/gap > SHAPE_TRUST/DOUBT``), and ``M⁻¹`` (its factorisation's ``solve``) for the
    check that follows. Resolved pairs cost one residual; each doubtful one a solve."""
    mass_solve = factorise(M).solve
    pick = np.arange(min(rigid, lam.size), min(lam.size, rigid + CHECKED))
    eta, angle = residual_bounds(K, M, lam[pick], np.asarray(phi)[:, pick], mass_solve)
    doubt = pick[(eta > TRUST / DOUBT * np.maximum(lam[pick], 1e-300))
                 | (angle > SHAPE_TRUST / DOUBT)]
    phi = np.array(phi, dtype=float, copy=True)
    if doubt.size:
        phi[:, doubt] = refine_pairs(K, M, lam[doubt], phi[:, doubt], solve)
    return phi, mass_solve


def refine_pairs(K: sp.spmatrix, M: sp.spmatrix, lam: Array, phi: Array, solve: Any,
                 count: int = CHECKED) -> Array:
    """``phi`` with its lowest ``count`` vectors after one step of iterative refinement.

    ``φ ← φ − A⁻¹ r``, ``r = K φ − λ M φ`` summed in extended precision and ``A⁻¹`` the
    factorisation ``solve`` (of ``K − σ M``), is one step of shifted inverse iteration
    ``(λ − σ) A⁻¹ M φ`` whose only rounding is that of the correction: a vector from a
    Lanczos solver carries the solves' backward error ``ε |L||Lᵀ| |φ|`` in its residual,
    large where the net has small cells (a pole), and the step reduces it by about
    ``ε κ`` (mixed-precision iterative refinement, Wilkinson; it needs ``ε κ < 1``).
    The vectors are ``M``-normalised again; ``λ`` is kept (the shift-invert Ritz values
    are accurate to ``r²/gap``). The residuals are formed one vector at a time
    (``nnz(K)`` extended numbers: faster than strided blocks), the corrections in one solve.
    """
    K, M = sp.csr_matrix(K), sp.csr_matrix(M)
    phi = np.array(phi, dtype=float, copy=True)
    m = min(count, phi.shape[1])
    R = np.empty((phi.shape[0], m))
    for j in range(m):                             # one sparse product per mode
        X = phi[:, j:j + 1]
        R[:, j:j + 1] = _extended_product(K, X) - _extended_product(M, X) * np.longdouble(lam[j])
    X = phi[:, :m] - solve(R)
    phi[:, :m] = X / np.sqrt(np.einsum("ik,ik->k", X, M @ X))[None, :]
    return phi
