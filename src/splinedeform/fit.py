"""Fitting a control net to a parametric map: three separable methods, and the fit error.

A parametric map ``f(u, v) -> (..., 3)`` is turned into a control net ``P`` of a
tensor-product spline ``x(u,v) = Σ_k Σ_l p_kl b_k(u) b_l(v)`` by one of three methods,
each separable (one 1-D operator per direction, never a 2-D dense solve):

``"interpolate"``
    Collocation at the abscissae ``ξ_k`` of :meth:`BSplineBasis.greville`:
    ``B_u P B_vᵀ = X`` with ``(B_u)_{ik} = b_k(ξ_i)``, ``X_ij = f(ξ_i, η_j)``, solved
    as ``P = B_u^{-1} X B_v^{-T}`` (two sparse LU solves).
``"l2"``
    L2 projection ``(G0u ⊗ G0v) P = R`` with ``R_kl = ∫∫ f b_k b_l`` (tensor
    Gauss–Legendre, ``n + 3`` points per cell), i.e. ``G0u P G0v = R``.
``"quasi"``
    A local quasi-interpolant ``p_kl = Σ_i Σ_j w^u_{ki} w^v_{lj} f(s_i, t_j)``: for every
    basis function the weights are a row of the inverse of a small collocation matrix of
    the ``2n + 1`` functions living on ``n + 1`` knot spans of its support (Lyche–Schumaker /
    Lyche–Mørken local interpolation, see :func:`quasi_weights`). It reproduces every
    spline of the space, hence polynomials of degree ``n``, and converges at order ``n + 1``
    like the two global methods, for all three knot layouts; each coefficient depends on
    ``f`` near its own support only.

``fit_error`` is the largest distance ``|x(u,v) - f(u,v)|`` on a sample with 4 points per
cell plus the end points. A periodic direction needs the map closed over it
(:func:`_check_closed`). The public names are re-exported from :mod:`splinedeform.shapes`.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from numpy.typing import ArrayLike, NDArray

from .basis import KNOT_KINDS, BSplineBasis
from .errors import InputError
from .quadrature import gauss_points, gram_matrix
from .surface import Surface

Domain = tuple[tuple[float, float], tuple[float, float]]
Map = Callable[[NDArray[np.float64], NDArray[np.float64]], ArrayLike]
FIT_METHODS: tuple[str, ...] = ("interpolate", "l2", "quasi")
POINT_METHODS: tuple[str, ...] = ("interpolate", "l2")
DEFAULT_CELLS = (8, 8)
#: default cells of the shapes closed in ``u`` (a full turn needs more cells)
CLOSED_CELLS = (16, 8)
#: sample points per cell used for ``fit_error``
ERROR_SAMPLES_PER_CELL = 4


# -- argument handling ---------------------------------------------------------------------
def _pair(value: Any, what: str) -> tuple[Any, Any]:
    """``value`` if it is a pair, else ``(value, value)``."""
    if isinstance(value, (str, bytes)) or np.ndim(value) == 0:
        return value, value
    items = tuple(value)
    if len(items) != 2:
        raise InputError(f"{what} must be one value or a pair (u, v), got {value!r}")
    return items[0], items[1]


def _positive(value: Any, what: str) -> float:
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise InputError(f"{what} must be a positive number, got {value!r}") from None
    if not np.isfinite(number) or number <= 0:
        raise InputError(f"{what} must be a positive finite number, got {value!r}")
    return number


def _check_method(method: str, allowed: tuple[str, ...] = FIT_METHODS) -> str:
    if method not in allowed:
        raise InputError(f"fitting method must be one of {allowed}, got {method!r}")
    return method


def _knot_kinds(knots: Any) -> tuple[str, str]:
    """Resolve ``knots`` (one layout or a pair) into ``(kind_u, kind_v)``.

    Any layout is accepted in any direction here; ``"periodic"`` additionally needs the
    map (or point grid) to be closed in that direction, which :func:`_check_closed` and
    :func:`_check_grid_closed` verify once the map is known.
    """
    kinds = _pair(knots, "knots")
    for direction, kind in zip("uv", kinds):
        if kind not in KNOT_KINDS:
            raise InputError(f"knot layout in {direction} must be one of {KNOT_KINDS}, "
                             f"got {kind!r}")
    return kinds[0], kinds[1]


def _bases(cells: Any, degree: int, kinds: tuple[str, str],
           lengths: tuple[float, float]) -> tuple[BSplineBasis, BSplineBasis]:
    """The two bases, with errors naming the direction."""
    counts = _pair(cells, "cells")
    out = []
    for direction, m, kind, length in zip("uv", counts, kinds, lengths):
        if isinstance(m, (float, np.floating)) and float(m).is_integer():
            m = int(m)
        try:
            out.append(BSplineBasis(degree, m, length, kind))
        except InputError as exc:
            raise InputError(f"{direction} direction: {exc}") from None
    return out[0], out[1]


# -- evaluation of the map -------------------------------------------------------------------
def _sample_map(f: Map, u: NDArray[np.float64], v: NDArray[np.float64],
                origin: tuple[float, float] = (0.0, 0.0)) -> NDArray[np.float64]:
    """``f`` on the tensor grid ``u × v`` (shifted by ``origin``) as ``(len(u), len(v), 3)``."""
    U, V = np.meshgrid(origin[0] + u, origin[1] + v, indexing="ij")
    try:
        values = f(U, V)
        if np.iscomplexobj(values):
            raise InputError("the map f(u, v) returned complex values; a surface is real "
                             "(take .real explicitly if the imaginary part is meant to go)")
        X = np.asarray(values, dtype=float)
    except InputError:
        raise
    except Exception as exc:  # the user's map failed: say so without a deep traceback
        raise InputError(f"the map f(u, v) raised {type(exc).__name__}: {exc}") from None
    expected = U.shape + (3,)
    if X.shape != expected:
        hint = (" (stack the coordinates on the last axis: np.stack([x, y, z], axis=-1))"
                if X.shape == (3,) + U.shape else "")
        raise InputError(f"the map f(u, v) must return an array of shape {expected} for "
                         f"parameter arrays of shape {U.shape}, got {X.shape}{hint}")
    if not np.all(np.isfinite(X)):
        i, j = np.argwhere(~np.all(np.isfinite(X), axis=-1))[0]
        raise InputError(f"the map f(u, v) is not finite at (u, v) = "
                         f"({U[i, j]:g}, {V[i, j]:g})")
    return X


def error_samples(basis: BSplineBasis) -> NDArray[np.float64]:
    """``4 m + 1`` equally spaced parameters of ``[0, L]`` (4 per cell plus the end point)."""
    return np.linspace(0.0, basis.length, ERROR_SAMPLES_PER_CELL * basis.cells + 1)


def fit_error(surface: Surface, f: Map, origin: tuple[float, float] = (0.0, 0.0)) -> float:
    """``max |x(u,v) - f(u + u0, v + v0)|`` over :func:`error_samples` in both directions."""
    u, v = error_samples(surface.basis_u), error_samples(surface.basis_v)
    diff = surface.evaluate_grid(u, v) - _sample_map(f, u, v, origin)
    return float(np.linalg.norm(diff, axis=-1).max())


# -- 1-D building blocks (all fits are Kronecker products of these) -------------------------
def _solve_both(Au: sp.spmatrix, Av: sp.spmatrix, R: NDArray[np.float64]) -> NDArray[np.float64]:
    """``P`` with ``A_u P A_vᵀ = R`` (``R`` of shape ``(n_u, n_v, c)``): two sparse LU solves."""
    n_u, n_v, c = R.shape
    left = spla.splu(sp.csc_matrix(Au)).solve(R.reshape(n_u, n_v * c))        # A_u^{-1} R
    tmp = left.reshape(n_u, n_v, c).transpose(1, 0, 2).reshape(n_v, n_u * c)
    right = spla.splu(sp.csc_matrix(Av)).solve(tmp)                              # A_v^{-1} (.)ᵀ
    return right.reshape(n_v, n_u, c).transpose(1, 0, 2)


def _apply_both(Wu: sp.spmatrix, Wv: sp.spmatrix, X: NDArray[np.float64]) -> NDArray[np.float64]:
    """``W_u X W_vᵀ`` for ``X`` of shape ``(N_u, N_v, c)``."""
    N_u, N_v, c = X.shape
    tmp = np.asarray(Wu @ X.reshape(N_u, N_v * c)).reshape(-1, N_v, c)
    n_u = tmp.shape[0]
    out = np.asarray(Wv @ tmp.transpose(1, 0, 2).reshape(N_v, n_u * c))
    return out.reshape(-1, n_u, c).transpose(1, 0, 2)


def quasi_weights(basis: BSplineBasis) -> tuple[sp.csr_matrix, NDArray[np.float64]]:
    """Weights ``W`` and nodes ``s`` of the local quasi-interpolant ``c_k = Σ_i W_ki f(s_i)``.

    For function ``k`` take a window ``I_k`` of ``w = min(n+1, m)`` knot spans of
    ``[0, L]`` (``min(n+1, m-n)`` when periodic): its support when that lies inside
    ``[0, L]``, else the ``w`` spans at the end of ``[0, L]`` it overlaps. The ``D = w + n``
    functions ``b_j`` not vanishing on ``I_k`` span the splines on it; interpolate ``f``
    there at the ``D`` Greville abscissae of a clamped knot vector on ``I_k`` (well
    conditioned), i.e. solve ``A c = f(s)`` with ``A_{rj} = b_j(s_r)``, and keep ``c_k``:
    the weights are row ``k`` of ``A^{-1}`` (Lyche–Schumaker / Lyche–Mørken local
    interpolation). Any spline ``Σ c_j b_j`` agrees on ``I_k`` with its local part, so it is
    reproduced exactly (polynomial precision ``n``, order ``n + 1``). For the interior of a
    uniform cubic basis the weights are the fixed stencil of a whole-support rule.
    """
    n, m, h = basis.degree, basis.cells, basis.h
    k = np.arange(basis.size)
    if basis.periodic:
        w = min(n + 1, m - n)                  # the D = w + n local functions are distinct
        start = k + (n + 1 - w) // 2           # function k lives on cells k..k+n (mod m)
        active = np.mod(start[:, None] - n + np.arange(w + n), m)
    else:
        w = min(n + 1, m)
        start = np.clip(k - n, 0, m - w)       # function k lives on cells k-n..k
        active = start[:, None] + np.arange(w + n)
    local = BSplineBasis(n, w, w * h, "open").greville()                 # (D,)
    x = start[:, None] * h + local                                       # (size, D)
    if basis.periodic:
        x = np.mod(x, basis.length)
    A = _local_collocation(basis, x, active)                             # (size, D, D)
    position = np.argmax(active == k[:, None], axis=1)
    weights = np.linalg.inv(A)[k, position, :]                           # (size, D)
    nodes, where = _merge_nodes(x.ravel(), 1e-12 * h)
    W = sp.csr_matrix((weights.ravel(), (np.repeat(k, w + n), where)),
                      shape=(basis.size, nodes.size))
    W.sum_duplicates()
    return W, nodes


def _merge_nodes(x: NDArray[np.float64], tol: float
                 ) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    """Distinct values of ``x`` (closer than ``tol`` counts as equal) and each one's index."""
    order = np.argsort(x)
    group = np.concatenate([[0], np.cumsum(np.diff(x[order]) > tol)])
    where = np.empty_like(group)
    where[order] = group
    first = np.concatenate([[True], np.diff(group) > 0])
    return x[order][first], where


def _local_collocation(basis: BSplineBasis, x: NDArray[np.float64],
                       functions: NDArray[np.int64]) -> NDArray[np.float64]:
    """``A[k, r, j] = b_{functions[k, j]}(x[k, r])`` (zero outside the support)."""
    index, values = basis.nonzero(x)                                     # (size, D, n+1)
    match = index[:, :, :, None] == functions[:, None, None, :]          # (size, D, n+1, D)
    return np.einsum("krq,krqj->krj", values, match.astype(float))


def _projection_weights(basis: BSplineBasis, points_per_cell: int
                        ) -> tuple[sp.csr_matrix, NDArray[np.float64]]:
    """``W = B^T diag(w)`` for Gauss points ``x``, so that ``(W f(x))_k ≈ ∫ f b_k``."""
    x, w = gauss_points(basis, points_per_cell)
    return (basis.matrix(x).T @ sp.diags(w)).tocsr(), x


# -- fitting ------------------------------------------------------------------------------
def fit_control_points(f: Map, basis_u: BSplineBasis, basis_v: BSplineBasis,
                       method: str = "interpolate",
                       origin: tuple[float, float] = (0.0, 0.0)) -> NDArray[np.float64]:
    """Control net ``(n_u, n_v, 3)`` of ``f(u0 + u, v0 + v)`` on the two bases.

    Parameters
    ----------
    f : callable
        Vectorised map ``f(U, V) -> (..., 3)`` for parameter arrays ``U, V`` of one shape.
    basis_u, basis_v : BSplineBasis
    method : {"interpolate", "l2", "quasi"}
        See the module docstring: ``B_u P B_vᵀ = X`` at Greville points,
        ``G0u P G0v = ∫∫ f b_k b_l``, or the local rule ``P = W_u F W_vᵀ``.
    origin : (float, float)
        Parameter ``(u0, v0)`` of ``f`` at the surface parameter ``(0, 0)``.
    """
    _check_method(method)
    if method == "interpolate":
        gu, gv = basis_u.greville(), basis_v.greville()
        Bu, Bv = basis_u.matrix(gu), basis_v.matrix(gv)
        return _solve_both(Bu, Bv, _sample_map(f, gu, gv, origin))
    if method == "l2":
        Wu, xu = _projection_weights(basis_u, basis_u.degree + 3)
        Wv, xv = _projection_weights(basis_v, basis_v.degree + 3)
        R = _apply_both(Wu, Wv, _sample_map(f, xu, xv, origin))
        return _solve_both(gram_matrix(basis_u, 0), gram_matrix(basis_v, 0), R)
    Wu, su = quasi_weights(basis_u)
    Wv, sv = quasi_weights(basis_v)
    return _apply_both(Wu, Wv, _sample_map(f, su, sv, origin))


def _domain(domain: Any) -> Domain:
    try:
        (a, b), (c, d) = domain
        a, b, c, d = (float(t) for t in (a, b, c, d))
    except (TypeError, ValueError):
        raise InputError(f"domain must be ((u_min, u_max), (v_min, v_max)), "
                         f"got {domain!r}") from None
    if not all(np.isfinite([a, b, c, d])) or b <= a or d <= c:
        raise InputError(f"domain must be finite with u_min < u_max and v_min < v_max, "
                         f"got {domain!r}")
    return (a, b), (c, d)


#: a periodic direction is closed when the seam gap is below this fraction of the extent
CLOSURE_TOLERANCE = 1e-8


def _check_closed(f: Map, basis_u: BSplineBasis, basis_v: BSplineBasis,
                  origin: tuple[float, float] = (0.0, 0.0)) -> None:
    """Refuse a periodic direction in which ``f`` is not closed.

    Closed in ``u`` means ``x(0, v) = x(L_u, v)`` for every ``v``: the gap
    ``max_v |f(u0 + L_u, v) - f(u0, v)|`` (on :func:`error_samples`) must stay below
    ``CLOSURE_TOLERANCE`` times the extent of the sampled map; likewise in ``v``.
    """
    if not (basis_u.periodic or basis_v.periodic):
        return
    u, v = error_samples(basis_u), error_samples(basis_v)
    X = _sample_map(f, u, v, origin)
    extent = float(np.ptp(X.reshape(-1, 3), axis=0).max())
    for axis, (basis, other, names) in enumerate(((basis_u, v, "uv"), (basis_v, u, "vu"))):
        if not basis.periodic:
            continue
        gaps = np.linalg.norm(np.take(X, -1, axis=axis) - np.take(X, 0, axis=axis), axis=-1)
        worst = int(np.argmax(gaps))
        if gaps[worst] > CLOSURE_TOLERANCE * max(extent, np.finfo(float).tiny):
            d, o = names
            raise InputError(
                f"knots in {d} are 'periodic' but the shape is not closed in {d}: x({d} = 0) "
                f"and x({d} = {basis.length:g}) are {gaps[worst]:.3g} apart at {o} = "
                f"{other[worst]:g} (shape extent {extent:.3g}); use 'open' or 'uniform' knots "
                f"in {d}, or a map that is periodic over that side")


def _fitted(f: Map, basis_u: BSplineBasis, basis_v: BSplineBasis, method: str, name: str,
            origin: tuple[float, float] = (0.0, 0.0)) -> Surface:
    _check_closed(f, basis_u, basis_v, origin)
    P = fit_control_points(f, basis_u, basis_v, method, origin)
    surface = Surface(P, basis_u, basis_v, name=name)
    return Surface(P, basis_u, basis_v, fit_error=fit_error(surface, f, origin), name=name)
