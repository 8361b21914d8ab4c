"""NURBS surfaces whose weights do not factor: the rational basis of a weighted net.

With weights ``w_kl`` (one per control point) on two polynomial bases ``N_k(u)``,
``N_l(v)`` the surface and its basis are

.. math:: x = \\frac{\\sum_{kl} w_{kl} N_k N_l p_{kl}}{W}, \\qquad
          R_{kl} = \\frac{w_{kl} N_k N_l}{W}, \\qquad W = \\sum_{kl} w_{kl} N_k N_l.

Both are quotients ``f = A / W`` of polynomial numerators; their derivatives follow from
Leibniz' rule applied to ``A = W f`` (Piegl & Tiller, *The NURBS Book*, eq. 4.20):

.. math:: D^{(p,q)} f = \\Big(D^{(p,q)} A - \\sum_{(i,j) \\ne (0,0)}^{(p,q)}
          \\binom{p}{i}\\binom{q}{j} D^{(i,j)} W \\, D^{(p-i,q-j)} f\\Big) / W.

Points are evaluated in homogeneous coordinates ``(w p, w)`` on the polynomial bases
(every fast path of :class:`~splinedeform.surface.Surface` serves the numerator), the
basis ``R_kl`` from its local functions (:func:`basis_derivatives`), which the plate
(:mod:`splinedeform.physics.rational_plate`), the intrinsic physics, the Kirchhoff–Love
shell (:mod:`splinedeform.physics.shell`, through the metric's grid) and the evaluation
matrices share. Weights of the form ``a_k b_l`` keep per-direction
:class:`~splinedeform.knots.RationalBasis` objects instead (:func:`product_factors`).
"""

from __future__ import annotations

from dataclasses import replace
from math import comb
from typing import TYPE_CHECKING, Callable, Iterable

import numpy as np
import scipy.sparse as sp
from numpy.typing import ArrayLike, NDArray

from .deboor import BLOCK
from .errors import InputError

if TYPE_CHECKING:
    from .surface import Surface

Array = NDArray[np.float64]
Order = tuple[int, int]
#: relative tolerance for weights to count as a product ``a_k b_l``
PRODUCT_TOL = 1e-12


def product_factors(w: ArrayLike, tol: float = PRODUCT_TOL) -> tuple[Array, Array] | None:
    """Factors ``a, b`` with ``w = a bᵀ`` within ``tol · max w`` (one ``b_l`` is 1), or None."""
    w = np.asarray(w, dtype=float)
    j = int(np.argmax(w.max(axis=0)))
    a = w[:, j].copy()
    b = w[int(np.argmax(a))] / a.max()
    if np.abs(w - np.outer(a, b)).max() > tol * w.max():
        return None
    return a, b


def check_weights(w: ArrayLike, shape: tuple[int, int], what: str = "net_weights") -> Array:
    """``w`` as a read-only float array of ``shape``, finite and > 0 (else InputError)."""
    w = np.array(w, dtype=float)
    if w.shape != shape:
        raise InputError(f"{what} must have shape {shape} (one weight per control point), "
                         f"got {w.shape}")
    if not np.all(np.isfinite(w)) or np.any(w <= 0):
        bad = tuple(int(i) for i in np.argwhere(~(np.isfinite(w) & (w > 0)))[0])
        raise InputError(f"NURBS weights must be finite and > 0; {what}{list(bad)} is {w[bad]}")
    w.setflags(write=False)
    return w


def clamped(basis: object) -> bool:
    """Whether a 1-D basis is periodic or its end knots repeat ``n + 1`` times (so only
    the end function is non-zero at each end, as the edge conditions of general weights
    assume)."""
    if getattr(basis, "periodic", False):
        return True
    n, t = basis.degree, np.asarray(basis.knots, dtype=float)      # type: ignore[attr-defined]
    return bool(np.all(t[:n + 1] == t[n]) and np.all(t[-n - 1:] == t[-n - 1]))


def lower_orders(targets: Iterable[Order]) -> list[Order]:
    """Every ``(i, j) <= (p, q)`` of some target, in an order Leibniz' rule can follow."""
    wanted = {(i, j) for p, q in targets for i in range(p + 1) for j in range(q + 1)}
    return sorted(wanted, key=lambda o: (o[0] + o[1], o))


def quotient(A: Callable[[Order], Array], W: Callable[[Order], Array],
             targets: Iterable[Order]) -> dict[Order, Array]:
    """``D^(p,q) (A / W)`` for the targets and every lower order (module docstring).

    ``A(order)`` and ``W(order)`` give the derivatives of numerator and denominator; ``W``'s
    broadcast against ``A``'s (a trailing axis of length 1).
    """
    Wd = {o: W(o) for o in lower_orders(targets)}
    out: dict[Order, Array] = {}
    for p, q in lower_orders(targets):
        acc = np.array(A((p, q)), dtype=float)
        for i in range(p + 1):
            for j in range(q + 1):
                if i or j:
                    acc -= comb(p, i) * comb(q, j) * Wd[i, j] * out[p - i, q - j]
        out[p, q] = acc / Wd[0, 0]
    return out


def basis_derivatives(iu: NDArray[np.int64], Bu: Array, iv: NDArray[np.int64], Bv: Array,
                      weights: Array, targets: Iterable[Order]
                      ) -> tuple[NDArray[np.int64], dict[Order, Array]]:
    """``D^(p,q) R_kl`` of the local functions at points given by their 1-D values.

    ``iu (..., pu)`` and ``Bu (orders, ..., pu)`` (orders ``0..max p``), likewise in v,
    broadcast to a common point shape ``S`` (a grid: ``Bu[:, :, None]`` and
    ``Bv[:, None]``). Returns the flat index ``k n_v + l`` of each local function,
    ``S + (pu pv,)``, and ``{(p, q): S + (pu pv,)}`` for the targets and lower orders, from
    ``A_kl = w_kl D^p N_k D^q N_l`` and ``W = Σ A_kl``.
    """
    local_w = weights[iu[..., :, None], iv[..., None, :]]               # S + (pu, pv)
    shape = local_w.shape[:-2] + (-1,)

    numerators: dict[Order, Array] = {}

    def A(order: Order) -> Array:
        if order not in numerators:
            p, q = order
            numerators[order] = (Bu[p][..., :, None] * Bv[q][..., None, :]
                                 * local_w).reshape(shape)
        return numerators[order]

    R = quotient(A, lambda o: A(o).sum(axis=-1, keepdims=True), targets)
    index = (iu[..., :, None] * weights.shape[1] + iv[..., None, :]).reshape(shape)
    return np.broadcast_to(index, R[0, 0].shape), R


def polynomial(surface: Surface) -> Surface:
    """The surface on the same bases without its weights (evaluates homogeneous nets)."""
    twin = surface._cache.get("polynomial")
    if twin is None:
        twin = surface._cache["polynomial"] = replace(surface, net_weights=None)
    return twin


def homogeneous(surface: Surface, control_points: ArrayLike | None = None) -> Array:
    """The net ``(w p, w)``, ``(n_u, n_v, c + 1)``, of the surface's (or another) net."""
    P = surface.control_points if control_points is None else np.asarray(control_points, float)
    w = surface.net_weights
    P = P.reshape(w.shape + (-1,))
    return np.concatenate([P * w[..., None], w[..., None]], axis=-1)


def _from_homogeneous(evaluate: Callable[[int, int], Array], du: int, dv: int) -> Array:
    """``D^(du,dv)`` of ``x = A / W`` from the homogeneous derivatives ``evaluate(i, j)``."""
    cache: dict[Order, Array] = {}

    def part(order: Order) -> Array:
        if order not in cache:
            cache[order] = evaluate(*order)
        return cache[order]

    return quotient(lambda o: part(o)[..., :-1], lambda o: part(o)[..., -1:],
                    [(du, dv)])[du, dv]


def derivative(surface: Surface, u: ArrayLike, v: ArrayLike, du: int = 0, dv: int = 0,
               control_points: ArrayLike | None = None) -> Array:
    """``∂^{du+dv} x / ∂u^du ∂v^dv`` at points ``(u, v)`` (broadcast), ``S + (c,)``.

    ``control_points`` is another net on the same rational basis (``Σ R_kl d_kl``); its
    trailing axes after ``(n_u, n_v)`` (several nets, ``(n_u, n_v, F, 3)``) are kept,
    ``S + (F, 3)``, as for polynomial bases.
    """
    twin, hom = polynomial(surface), homogeneous(surface, control_points)
    out = _from_homogeneous(lambda i, j: twin.derivative(u, v, i, j, control_points=hom),
                            du, dv)
    return out.reshape(out.shape[:-1] + _trailing(surface, control_points))


def _trailing(surface: Surface, control_points: ArrayLike | None) -> tuple[int, ...]:
    """The axes of a net after its ``(n_u, n_v)`` (``(3,)`` for the surface's own)."""
    if control_points is None:
        return surface.control_points.shape[2:]
    return np.shape(control_points)[2:]


def evaluate_grid(surface: Surface, u: ArrayLike, v: ArrayLike, du: int = 0, dv: int = 0,
                  control_points: ArrayLike | None = None) -> Array:
    """Tensor grid evaluation of :func:`derivative`, ``(len(u), len(v), c)``."""
    twin, hom = polynomial(surface), homogeneous(surface, control_points)
    out = _from_homogeneous(lambda i, j: twin.evaluate_grid(u, v, i, j, control_points=hom),
                            du, dv)
    return out.reshape(out.shape[:-1] + _trailing(surface, control_points))


def grid_nets(surface: Surface, u: ArrayLike, v: ArrayLike, nets: ArrayLike) -> Array:
    """``Σ_kl R_kl(u_i, v_j) P_kl`` of many nets ``(..., n_u, n_v, c)`` on the grid ``u × v``.

    ``X = B_u P B_vᵀ`` per net and coordinate with the 1-D matrices built once; with general
    weights ``X = B_u (w P) B_vᵀ / (B_u w B_vᵀ)``. Returns ``(..., len(u), len(v), c)``.
    """
    Bu = surface.basis_u.matrix(u).toarray()
    Bv = surface.basis_v.matrix(v).toarray()
    P = np.asarray(nets, dtype=float)
    w = surface.net_weights
    if w is None:
        return np.einsum("ik,...klc,jl->...ijc", Bu, P, Bv, optimize=True)
    X = np.einsum("ik,...klc,jl->...ijc", Bu, P * w[..., None], Bv, optimize=True)
    return X / (Bu @ w @ Bv.T)[..., None]


def weight_field(surface: Surface, U: ArrayLike, V: ArrayLike) -> Array:
    """The denominator ``W(u, v) = Σ w_kl N_k N_l`` at the points ``(U, V)``."""
    w = surface.net_weights
    return polynomial(surface).derivative(U, V, control_points=w[..., None])[..., 0]


def evaluation_matrix(surface: Surface, u: ArrayLike, v: ArrayLike, du: int = 0,
                      dv: int = 0) -> sp.csr_matrix:
    """Sparse ``E_{i, k n_v + l} = D^(du,dv) R_kl(u_i, v_i)`` (points flattened)."""
    u, v = np.broadcast_arrays(np.asarray(u, dtype=float), np.asarray(v, dtype=float))
    u, v = u.ravel(), v.ravel()
    bu, bv = surface.basis_u, surface.basis_v
    values, cols = [], []
    for start in range(0, u.size, BLOCK):
        block = slice(start, start + BLOCK)
        iu, Bu = bu.nonzero_derivatives(u[block], du)
        iv, Bv = bv.nonzero_derivatives(v[block], dv)
        index, R = basis_derivatives(iu, Bu, iv, Bv, surface.net_weights, [(du, dv)])
        values.append(R[du, dv])
        cols.append(index)
    width = (bu.degree + 1) * (bv.degree + 1)
    data = np.concatenate(values).ravel() if values else np.zeros(0)
    indices = np.concatenate(cols).ravel() if cols else np.zeros(0, dtype=np.int64)
    indptr = np.arange(0, u.size * width + 1, width)
    return sp.csr_matrix((data, indices, indptr), shape=(u.size, bu.size * bv.size))


def rational_operators(V: sp.spmatrix, derivatives: Iterable[sp.spmatrix], weights: Array
                       ) -> tuple[sp.csr_matrix, list[sp.csr_matrix]]:
    """First-order rational operators from polynomial ones on the same points.

    ``V`` (values) and each first derivative ``D`` map the flat net to points by the
    polynomial basis ``N``; with ``A = N diag(w)``, ``W = N w`` and ``W' = D w`` the quotient
    rule gives ``R = diag(1/W) A`` and ``R' = diag(1/W) (D diag(w) − diag(W') R)``. One-sided
    polynomial derivatives (at a knot line) give the one-sided rational ones.
    """
    w = np.asarray(weights, dtype=float).ravel()
    scale = sp.diags(w)
    inverse = sp.diags(1.0 / (V @ w))
    R = (inverse @ V @ scale).tocsr()
    return R, [(inverse @ (D @ scale - sp.diags(D @ w) @ R)).tocsr() for D in derivatives]

