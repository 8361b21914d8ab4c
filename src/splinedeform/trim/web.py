"""Höllig's weighted extended B-splines (WEB-splines) on a trimmed knot grid.

Uniform B-splines ``b_k`` of degree ``n`` on the grid (index ``k = (k_1, k_2)``, function
``k_ν`` supported on cells ``k_ν - n .. k_ν``) fall in three sets:

* **irrelevant**: no cell of the support meets ``Ω`` (dropped);
* **inner** ``I``: a whole cell of the support lies inside ``Ω`` (kept);
* **outer** ``J``: the support meets ``Ω`` only in cut cells.

Each outer ``j`` is tied to the ``(n+1)²`` array ``l + {0..n}²`` of inner indices closest
to it by the extension coefficients ``e_{i,j} = e^1_{i_1,j_1} e^2_{i_2,j_2}``, exact for the
polynomials of degree ``n`` the B-splines reproduce: by Marsden's identity the coefficient
of a polynomial ``p`` of degree ``n`` on ``b_k`` is its polar form (blossom)
``P(t_{k+1}, …, t_{k+n})``, so with ``A_{a,e} = σ_e(t_{l+a+1}, …, t_{l+a+n})`` and
``c_e = σ_e(t_{j+1}, …, t_{j+n})`` (``σ_e`` the elementary symmetric polynomials, the
blossoms of ``x^e`` up to ``binom(n, e)``, which cancels) the coefficients of a direction
are ``e_{l+a, j} = (c A⁻¹)_a``. On uniform knots this is Lagrange interpolation in the
index (:func:`lagrange_coefficients`)

.. math:: e_{i,j} = \\prod_{ν=1}^{2} \\prod_{μ=0, μ≠i_ν-l_ν}^{n}
          \\frac{j_ν - l_ν - μ}{i_ν - l_ν - μ};

on open (clamped) or general knots only the polar form is exact. Degrees may differ by
direction (``n_1``, ``n_2``; arrays of ``(n_1+1) × (n_2+1)``).

and the WEB-spline of an inner ``i`` is
``B_i = (w / w(x_i)) (b_i + Σ_{j∈J} e_{i,j} b_j)`` with ``x_i`` the centre of an inside cell
of its support. The extension matrix ``E`` (all × inner) has the identity on the inner
rows and ``e_{i,j}`` on the outer rows, so a spline ``Σ_i c_i B_i`` is
``w Σ_k (E S c)_k b_k`` with ``S = diag(1/w(x_i))``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from numpy.lib.stride_tricks import sliding_window_view
from numpy.typing import NDArray

from ..errors import InputError
from .cells import CUT, INSIDE


Degrees = tuple[int, int]


def degrees_of(degree: int | Degrees) -> Degrees:
    """``(n_1, n_2)`` of one degree or a pair."""
    if isinstance(degree, (tuple, list)):
        return int(degree[0]), int(degree[1])
    return int(degree), int(degree)


def _support_any(mask: NDArray[np.bool_], degree: int | Degrees) -> NDArray[np.bool_]:
    """``out[k] = any(mask[k - a])`` over ``a ∈ {0..n_1} × {0..n_2}`` (cells of the support
    of ``b_k``)."""
    n1, n2 = degrees_of(degree)
    padded = np.pad(mask, ((n1, n1), (n2, n2)), constant_values=False)  # padded[t] = mask[t-n]
    return sliding_window_view(padded, (n1 + 1, n2 + 1)).any(axis=(-1, -2))


def live_table(classes: NDArray[np.int64], degree: int | Degrees) -> NDArray[np.bool_]:
    """The B-splines whose support meets ``Ω`` (inner or outer, not irrelevant): a table
    over the B-spline indices. A coefficient outside it moves nothing of the region."""
    return _support_any((classes == INSIDE) | (classes == CUT), degree)


def lagrange_coefficients(target: NDArray[np.float64], degree: int) -> NDArray[np.float64]:
    """``L_a(t) = Π_{μ≠a} (t - μ)/(a - μ)`` for ``a = 0..n``; shape ``t.shape + (n+1,)``."""
    t = np.asarray(target, dtype=float)[..., None]
    nodes = np.arange(degree + 1)
    out = np.ones(t.shape[:-1] + (degree + 1,))
    for mu in range(degree + 1):          # n+1 factors: a loop over the degree, not points
        factor = (t - mu) / np.where(nodes == mu, 1.0, nodes - mu)
        out *= np.where(nodes == mu, 1.0, factor)
    return out


def _symmetric(t: NDArray[np.float64]) -> NDArray[np.float64]:
    """``σ_e(t_1, …, t_n)``, ``e = 0..n``, of the last axis: the coefficients of
    ``Π_i (1 + t_i z)``; shape ``t.shape[:-1] + (n + 1,)``."""
    n = t.shape[-1]
    sigma = np.zeros(t.shape[:-1] + (n + 1,))
    sigma[..., 0] = 1.0
    for i in range(n):                    # n factors: a loop over the degree, not points
        sigma[..., 1:] = sigma[..., 1:] + t[..., i, None] * sigma[..., :-1]
    return sigma


def polar_coefficients(knots: NDArray[np.float64], degree: int, target: NDArray[np.int64],
                       corner: NDArray[np.int64]) -> NDArray[np.float64]:
    """``e_a = (c A⁻¹)_a``, ``a = 0..n``, of one direction (module docstring): the
    coefficient on ``b_target`` of the polynomial whose coefficients on
    ``b_corner … b_{corner+n}`` are given; shape ``(J, n + 1)``. The knots are centred and
    scaled on each block's knots, so ``A`` stays well conditioned."""
    n, t = degree, np.asarray(knots, dtype=float)
    if not len(target):
        return np.zeros((0, n + 1))
    offsets = 1 + np.arange(n)
    block = t[corner[:, None, None] + np.arange(n + 1)[None, :, None] + offsets]   # (J, n+1, n)
    own = t[target[:, None] + offsets]                                              # (J, n)
    centre = block.mean(axis=(1, 2))[:, None]
    scale = np.ptp(block.reshape(len(corner), -1), axis=1)[:, None]
    scale = np.where(scale > 0, scale, 1.0)
    A = _symmetric((block - centre[..., None]) / scale[..., None])                  # (J, a, e)
    c = _symmetric((own - centre) / scale)                                          # (J, e)
    return np.linalg.solve(np.swapaxes(A, 1, 2), c[..., None])[..., 0]


@dataclass(frozen=True)
class WebBasis:
    """Index sets and the extension matrix ``E`` of a trimmed grid.

    ``inner``/``outer`` are boolean tables over the ``(m_1+n_1) × (m_2+n_2)`` B-spline
    indices; ``extension`` is ``E`` (sparse, all × inner, inner in C order of ``inner``).
    """

    degree: int | Degrees
    inner: NDArray[np.bool_]
    outer: NDArray[np.bool_]
    extension: sp.csr_matrix

    @property
    def size(self) -> int:
        """Number of WEB-splines (inner indices)."""
        return int(self.inner.sum())


def web_basis(classes: NDArray[np.int64], degree: int | Degrees,
              allowed: NDArray[np.bool_] | None = None,
              knots: tuple[NDArray[np.float64], NDArray[np.float64]] | None = None,
              weights: NDArray[np.float64] | None = None) -> WebBasis:
    """Inner and outer B-splines of a classified grid and Höllig's extension matrix.

    ``degree`` is one degree or ``(n_1, n_2)``; ``knots`` the two knot vectors (None:
    uniform knots, where the polar form is Lagrange interpolation in the index);
    ``weights`` the NURBS weights ``w_k`` of a rational net (flat): a rational field
    ``Σ d_k w_k b_k / W`` is extended through its numerator's coefficients ``w_k d_k``, so
    ``E`` becomes ``diag(1/w) E diag(w_I)`` (polynomials over ``W`` reproduced).
    ``allowed`` (a table over the B-spline indices) restricts the arrays the outer
    B-splines are tied to (e.g. to coefficients an edge condition keeps free). Raises
    :class:`InputError` when no such array of inner indices exists (the grid is too coarse
    for the trimmed region).
    """
    n = degrees_of(degree)
    meets = live_table(classes, n)
    inner = _support_any(classes == INSIDE, n)
    outer = meets & ~inner
    shape = inner.shape
    number = -np.ones(shape, int)
    number[inner] = np.arange(inner.sum())
    # lower corners l of (n_1+1) × (n_2+1) blocks of inner indices
    candidates = inner if allowed is None else inner & allowed
    block = sliding_window_view(candidates, (n[0] + 1, n[1] + 1)).all(axis=(-1, -2))
    corners = np.argwhere(block)
    if not len(corners):
        raise InputError(f"the trimmed region holds no {n[0] + 1}×{n[1] + 1} array of inner "
                         "B-splines: refine the grid")
    out_idx = np.argwhere(outer)
    gap = out_idx[:, None, :] - (corners[None] + 0.5 * np.array(n))
    l = corners[np.argmin(np.sum(gap * gap, axis=-1), axis=1)]          # (J, 2)
    if knots is None:
        L1 = lagrange_coefficients(out_idx[:, 0] - l[:, 0], n[0])         # (J, n_1+1)
        L2 = lagrange_coefficients(out_idx[:, 1] - l[:, 1], n[1])
    else:
        L1 = polar_coefficients(knots[0], n[0], out_idx[:, 0], l[:, 0])
        L2 = polar_coefficients(knots[1], n[1], out_idx[:, 1], l[:, 1])
    e = L1[:, :, None] * L2[:, None, :]                                  # (J, n_1+1, n_2+1)
    cols = number[l[:, 0, None, None] + np.arange(n[0] + 1)[:, None],
                  l[:, 1, None, None] + np.arange(n[1] + 1)[None, :]]
    rows = np.ravel_multi_index(out_idx.T, shape)
    in_rows = np.flatnonzero(inner.ravel())
    E = sp.csr_matrix(
        (np.concatenate([np.ones(len(in_rows)), e.ravel()]),
         (np.concatenate([in_rows, np.repeat(rows, (n[0] + 1) * (n[1] + 1))]),
          np.concatenate([np.arange(len(in_rows)), cols.ravel()]))),
        shape=(inner.size, len(in_rows)))
    if weights is not None:
        w = np.asarray(weights, dtype=float).ravel()
        E = (sp.diags(1.0 / w) @ E @ sp.diags(w[in_rows])).tocsr()
    return WebBasis(degree, inner, outer, E)


def normalisation(classes: NDArray[np.int64], degree: int, weight_at_centres: NDArray[np.float64],
                  inner: NDArray[np.bool_]) -> NDArray[np.float64]:
    """``1 / w(x_i)`` for the inner indices, ``x_i`` the inside cell of the support where the
    weight (given at the cell centres, shape of ``classes``) is largest."""
    n = degree
    w = np.where(classes == INSIDE, weight_at_centres, -np.inf)
    best = sliding_window_view(np.pad(w, n, constant_values=-np.inf),
                               (n + 1, n + 1)).max(axis=(-1, -2))
    return 1.0 / best[inner]
