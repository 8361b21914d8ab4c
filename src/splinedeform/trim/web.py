"""Höllig's weighted extended B-splines (WEB-splines) on a trimmed knot grid.

Uniform B-splines ``b_k`` of degree ``n`` on the grid (index ``k = (k_1, k_2)``, function
``k_ν`` supported on cells ``k_ν - n .. k_ν``) fall in three sets:

* **irrelevant**: no cell of the support meets ``Ω`` (dropped);
* **inner** ``I``: a whole cell of the support lies inside ``Ω`` (kept);
* **outer** ``J``: the support meets ``Ω`` only in cut cells.

Each outer ``j`` is tied to the ``(n+1)²`` array ``l + {0..n}²`` of inner indices closest
to it by the extension coefficients (Lagrange interpolation in the index, exact for the
polynomials of degree ``n`` the B-splines reproduce)

.. math:: e_{i,j} = \\prod_{ν=1}^{2} \\prod_{μ=0, μ≠i_ν-l_ν}^{n}
          \\frac{j_ν - l_ν - μ}{i_ν - l_ν - μ},

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


def _support_any(mask: NDArray[np.bool_], degree: int) -> NDArray[np.bool_]:
    """``out[k] = any(mask[k - a])`` over ``a ∈ {0..n}²`` (cells of the support of ``b_k``)."""
    padded = np.pad(mask, degree, constant_values=False)    # padded[t] = mask[t - n]
    return sliding_window_view(padded, (degree + 1, degree + 1)).any(axis=(-1, -2))


def lagrange_coefficients(target: NDArray[np.float64], degree: int) -> NDArray[np.float64]:
    """``L_a(t) = Π_{μ≠a} (t - μ)/(a - μ)`` for ``a = 0..n``; shape ``t.shape + (n+1,)``."""
    t = np.asarray(target, dtype=float)[..., None]
    nodes = np.arange(degree + 1)
    out = np.ones(t.shape[:-1] + (degree + 1,))
    for mu in range(degree + 1):          # n+1 factors: a loop over the degree, not points
        factor = (t - mu) / np.where(nodes == mu, 1.0, nodes - mu)
        out *= np.where(nodes == mu, 1.0, factor)
    return out


@dataclass(frozen=True)
class WebBasis:
    """Index sets and the extension matrix ``E`` of a trimmed uniform grid.

    ``inner``/``outer`` are boolean tables over the ``(m_1+n) × (m_2+n)`` B-spline indices;
    ``extension`` is ``E`` (sparse, all × inner, inner in C order of ``inner``).
    """

    degree: int
    inner: NDArray[np.bool_]
    outer: NDArray[np.bool_]
    extension: sp.csr_matrix

    @property
    def size(self) -> int:
        """Number of WEB-splines (inner indices)."""
        return int(self.inner.sum())


def web_basis(classes: NDArray[np.int64], degree: int,
              allowed: NDArray[np.bool_] | None = None) -> WebBasis:
    """Inner and outer B-splines of a classified grid and Höllig's extension matrix.

    ``allowed`` (a table over the B-spline indices) restricts the ``(n+1)²`` arrays the
    outer B-splines are tied to (e.g. to coefficients an edge condition keeps free).
    Raises :class:`InputError` when no ``(n+1)²`` array of inner indices exists (the grid is
    too coarse for the trimmed region).
    """
    n = degree
    meets = _support_any((classes == INSIDE) | (classes == CUT), n)
    inner = _support_any(classes == INSIDE, n)
    outer = meets & ~inner
    shape = inner.shape
    number = -np.ones(shape, int)
    number[inner] = np.arange(inner.sum())
    # lower corners l of (n+1)² blocks of inner indices
    candidates = inner if allowed is None else inner & allowed
    block = sliding_window_view(candidates, (n + 1, n + 1)).all(axis=(-1, -2))
    corners = np.argwhere(block)
    if not len(corners):
        raise InputError(f"the trimmed region holds no {n + 1}×{n + 1} array of inner "
                         "B-splines: refine the grid")
    out_idx = np.argwhere(outer)
    gap = out_idx[:, None, :] - (corners[None] + 0.5 * n)
    l = corners[np.argmin(np.sum(gap * gap, axis=-1), axis=1)]          # (J, 2)
    L1 = lagrange_coefficients(out_idx[:, 0] - l[:, 0], n)               # (J, n+1)
    L2 = lagrange_coefficients(out_idx[:, 1] - l[:, 1], n)
    e = L1[:, :, None] * L2[:, None, :]                                  # (J, n+1, n+1)
    a = np.arange(n + 1)
    cols = number[l[:, 0, None, None] + a[:, None], l[:, 1, None, None] + a[None, :]]
    rows = np.ravel_multi_index(out_idx.T, shape)
    in_rows = np.flatnonzero(inner.ravel())
    E = sp.csr_matrix(
        (np.concatenate([np.ones(len(in_rows)), e.ravel()]),
         (np.concatenate([in_rows, np.repeat(rows, (n + 1) ** 2)]),
          np.concatenate([np.arange(len(in_rows)), cols.ravel()]))),
        shape=(inner.size, len(in_rows)))
    return WebBasis(n, inner, outer, E)


def normalisation(classes: NDArray[np.int64], degree: int, weight_at_centres: NDArray[np.float64],
                  inner: NDArray[np.bool_]) -> NDArray[np.float64]:
    """``1 / w(x_i)`` for the inner indices, ``x_i`` the inside cell of the support where the
    weight (given at the cell centres, shape of ``classes``) is largest."""
    n = degree
    w = np.where(classes == INSIDE, weight_at_centres, -np.inf)
    best = sliding_window_view(np.pad(w, n, constant_values=-np.inf),
                               (n + 1, n + 1)).max(axis=(-1, -2))
    return 1.0 / best[inner]
