"""Initial surfaces: fitting a control net to a map, a point grid, and built-in shapes.

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

Each built-in shape returns a :class:`~splinedeform.surface.Surface` whose ``fit_error``
is the largest distance ``|x(u,v) - f(u,v)|`` on a sample with 4 points per cell plus
the end points. Parameter domains always start at ``(0, 0)``; a closed direction uses
the period as its length so that the map is periodic over it.

``knots`` is one layout for both directions or a pair ``(knots_u, knots_v)``; ``cells``
is an integer or a pair ``(m_u, m_v)``.

Examples
--------
>>> surf = plane(size=(2.0, 1.0), cells=(4, 3))
>>> surf.shape, surf.fit_error < 1e-12
((7, 6), True)
"""

from __future__ import annotations

from collections.abc import Callable
from math import pi
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

__all__ = ["FIT_METHODS", "cylinder", "error_samples", "fit_control_points", "fit_error",
           "from_function", "from_points", "half_sphere", "plane", "quasi_weights", "saddle",
           "tile", "torus"]


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


def from_function(f: Map, cells: int | tuple[int, int] = DEFAULT_CELLS, degree: int = 3,
                  knots: str | tuple[str, str] = "open",
                  domain: Domain = ((0.0, 1.0), (0.0, 1.0)),
                  method: str = "interpolate", name: str | None = None) -> Surface:
    """Fit a spline surface to a parametric map ``f(u, v)`` on a parameter rectangle.

    Parameters
    ----------
    f : callable
        Vectorised ``f(U, V) -> array (..., 3)``; called with 2-D arrays of one shape.
    cells : int or (int, int)
        Knot spans ``(m_u, m_v)``.
    degree : int
        Polynomial degree ``n >= 1`` in both directions.
    knots : str or (str, str)
        ``"open"``, ``"uniform"`` or ``"periodic"`` per direction. ``"periodic"`` needs
        ``f`` periodic over that side of ``domain`` (refused, naming the gap, otherwise).
    domain : ((a, b), (c, d))
        Where ``f`` is sampled. The surface's own parameters are ``[0, b-a] × [0, d-c]``:
        surface parameter ``(u, v)`` is ``f``'s ``(a + u, c + v)``.
    method : {"interpolate", "l2", "quasi"}
        See the module docstring.
    name : str, optional
        Label of the surface (default ``"function"``).

    Returns
    -------
    Surface
        With ``fit_error = max |x - f|`` on 4 samples per cell plus the end points.

    Examples
    --------
    >>> import numpy as np
    >>> s = from_function(lambda u, v: np.stack([u, v, u * v], -1), cells=3, degree=2)
    >>> s.fit_error < 1e-12
    True
    """
    kinds = _knot_kinds(knots)
    (a, b), (c, d) = _domain(domain)
    bu, bv = _bases(cells, degree, kinds, (b - a, d - c))
    return _fitted(f, bu, bv, method, name or "function", (a, c))


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


# -- point grids ----------------------------------------------------------------------------
def from_points(grid: ArrayLike, cells: int | tuple[int, int] = DEFAULT_CELLS, degree: int = 3,
                knots: str | tuple[str, str] = "open", method: str = "interpolate",
                domain: Domain = ((0.0, 1.0), (0.0, 1.0)),
                name: str | None = None) -> Surface:
    """Fit a spline surface to a grid of points sampled evenly on the parameter domain.

    Point ``grid[i, j]`` is taken as ``x(u_i, v_j)`` with ``u_i = i L_u / (N_u - 1)``
    (``L_u = b - a`` of ``domain``; the surface's parameters start at 0). In a periodic
    direction the samples are ``u_i = i L_u / N_u`` unless the last row repeats the first
    (a closed grid), in which case the repeat is dropped.

    Parameters
    ----------
    grid : array_like, shape ``(N_u, N_v, 3)``
    cells, degree, knots, domain, name
        As in :func:`from_function`.
    method : {"interpolate", "l2"}
        ``"interpolate"``: collocation ``B_u P B_vᵀ = X`` when ``N`` equals the number of
        control points in a direction, least squares ``min |B_u P B_vᵀ - X|`` (solved per
        direction, ``P = B_u^+ X B_v^{+T}``) when there are more points.
        ``"l2"``: the discrete L2 projection, least squares weighted by the trapezoidal
        rule ``min Σ ω_i ω_j |x(u_i, v_j) - X_ij|²``.

    Returns
    -------
    Surface
        ``fit_error`` is the largest distance between the surface at the sample
        parameters and the given points.
    """
    _check_method(method, POINT_METHODS)
    if np.iscomplexobj(grid):
        raise InputError("point grid is complex; a surface is real (take .real explicitly if "
                         "the imaginary part is meant to go)")
    try:
        raw = np.asarray(grid)
    except (TypeError, ValueError) as exc:          # ragged nesting
        raise InputError(f"a point grid must be an array of real numbers of shape "
                         f"(N_u, N_v, 3): {exc}") from None
    if raw.dtype.kind not in "iuf":                 # numpy would parse strings like "1.5"
        raise InputError(f"a point grid must be an array of real numbers, got dtype "
                         f"{raw.dtype}")
    X = raw.astype(float)
    if X.ndim != 3 or X.shape[2] != 3 or X.shape[0] < 2 or X.shape[1] < 2:
        raise InputError(f"a point grid must have shape (N_u, N_v, 3) with N_u, N_v >= 2, "
                         f"got {X.shape}")
    if not np.all(np.isfinite(X)):
        i, j = np.argwhere(~np.all(np.isfinite(X), axis=-1))[0]
        raise InputError(f"point grid must be finite; point ({i}, {j}) is {X[i, j]}")
    kinds = _knot_kinds(knots)
    (a, b), (c, d) = _domain(domain)
    bu, bv = _bases(cells, degree, kinds, (b - a, d - c))
    X, u = _grid_parameters(X, bu, axis=0)
    X, v = _grid_parameters(X, bv, axis=1)
    Au = _least_squares_operator(bu, u, method, "u")
    Av = _least_squares_operator(bv, v, method, "v")
    _check_distinct(X)
    _check_grid_closed(X, bu, bv)
    P = _apply_both(Au, Av, X)
    surface = Surface(P, bu, bv, name=name or "points")
    error = float(np.linalg.norm(surface.evaluate_grid(u, v) - X, axis=-1).max())
    return Surface(P, bu, bv, fit_error=error, name=surface.name)


def _check_distinct(X: NDArray[np.float64]) -> None:
    """Refuse a grid of coincident points: all in one place, or a row/column repeated.

    A row ``X[i]`` equal to ``X[i + 1]`` (every point of it) gives two samples at different
    parameters at one place, so ``x_u = 0`` all along it; a single degenerate row (a pole,
    its points coinciding with each other) is allowed.
    """
    extent = float(np.ptp(X.reshape(-1, 3), axis=0).max())
    if extent == 0.0:
        raise InputError(f"point grid: all {X.shape[0] * X.shape[1]} points coincide at "
                         f"{X[0, 0].tolist()}; a surface needs points spread over an area")
    for axis, direction in ((0, "u"), (1, "v")):
        step = np.abs(np.diff(X, axis=axis)).max(axis=(1 - axis, 2))
        same = np.flatnonzero(step <= 1e-14 * extent)
        if same.size:
            i = int(same[0])
            what = "rows" if axis == 0 else "columns"
            raise InputError(f"point grid: {what} {i} and {i + 1} ({direction} direction) "
                             f"coincide point for point; remove the repeated samples")


def _check_grid_closed(X: NDArray[np.float64], basis_u: BSplineBasis,
                       basis_v: BSplineBasis) -> None:
    """Refuse a periodic direction on an open grid (seam already dropped).

    The step from the last sample back to the first must look like any other step: it
    may not exceed 3 times the largest step between neighbouring samples.
    """
    for axis, basis, direction in ((0, basis_u, "u"), (1, basis_v, "v")):
        if not basis.periodic:
            continue
        steps = np.linalg.norm(np.diff(X, axis=axis), axis=-1).max()
        gap = np.linalg.norm(np.take(X, 0, axis=axis) - np.take(X, -1, axis=axis),
                             axis=-1).max()
        if gap > 3 * steps:
            raise InputError(
                f"knots in {direction} are 'periodic' but the point grid is not closed in "
                f"{direction}: its last and first samples are {gap:.3g} apart, against at "
                f"most {steps:.3g} between neighbours; use 'open' or 'uniform' knots in "
                f"{direction}, or a grid that goes round")


def _grid_parameters(X: NDArray[np.float64], basis: BSplineBasis, axis: int
                     ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Sample parameters along ``axis`` (dropping a repeated seam when periodic)."""
    N = X.shape[axis]
    if not basis.periodic:
        return X, np.linspace(0.0, basis.length, N)
    first, last = np.take(X, 0, axis=axis), np.take(X, -1, axis=axis)
    scale = max(1.0, float(np.abs(X).max()))
    if np.allclose(first, last, rtol=0.0, atol=1e-12 * scale):
        X = np.take(X, np.arange(N - 1), axis=axis)
        N -= 1
    return X, np.arange(N) * (basis.length / N)


def _least_squares_operator(basis: BSplineBasis, x: NDArray[np.float64], method: str,
                            direction: str) -> NDArray[np.float64]:
    """``S`` with ``c = S y`` the (weighted) least-squares coefficients of samples ``y``."""
    if x.size < basis.size:
        raise InputError(
            f"{direction} direction: {x.size} sample(s) cannot determine {basis.size} control "
            f"points; give at least {basis.size} points or fewer cells / a lower degree")
    B = basis(x)
    if method == "l2":
        w = np.full(x.size, 1.0)
        if not basis.periodic:
            w[[0, -1]] = 0.5
        sqrt_w = np.sqrt(w)[:, None]
        B = B * sqrt_w
    else:
        sqrt_w = np.ones((x.size, 1))
    if np.linalg.cond(B) > 1e12:
        raise InputError(f"{direction} direction: the collocation matrix is singular; "
                         f"the sample parameters do not determine the control points")
    return np.linalg.pinv(B) * sqrt_w.T


# -- built-in shapes ------------------------------------------------------------------------
def plane(size: float | tuple[float, float] = (1.0, 1.0),
          cells: int | tuple[int, int] = DEFAULT_CELLS, degree: int = 3,
          knots: str | tuple[str, str] = "open", method: str = "interpolate") -> Surface:
    """The flat rectangle ``x(u, v) = (u, v, 0)`` on ``[0, L_u] × [0, L_v]``.

    Parameters
    ----------
    size : float or (L_u, L_v)
        Side lengths; the parameter domain is the rectangle itself.

    Every method reproduces it exactly for any degree ``n >= 1`` (linear precision);
    ``x_u × x_v = (0, 0, 1)``.
    """
    L_u, L_v = (_positive(s, "plane size") for s in _pair(size, "size"))
    kinds = _knot_kinds(knots)
    bu, bv = _bases(cells, degree, kinds, (L_u, L_v))

    def f(u: NDArray[np.float64], v: NDArray[np.float64]) -> NDArray[np.float64]:
        return np.stack([u, v, np.zeros_like(u)], axis=-1)

    return _fitted(f, bu, bv, _check_method(method), "plane")


def saddle(size: float | tuple[float, float] = (1.0, 1.0), height: float = 0.25,
           cells: int | tuple[int, int] = DEFAULT_CELLS, degree: int = 3,
           knots: str | tuple[str, str] = "open", method: str = "interpolate") -> Surface:
    """The hyperbolic paraboloid ``z = h (ξ² - η²)`` over a rectangle.

    ``x(u, v) = (u - L_u/2, v - L_v/2, h (ξ² - η²))`` with ``ξ = 2u/L_u - 1`` and
    ``η = 2v/L_v - 1`` in ``[-1, 1]``, on ``[0, L_u] × [0, L_v]``: ``z = 0`` at the
    corners, ``+h`` at the middles of the ``u`` ends and ``-h`` at the ``v`` ends.
    Quadratic in each parameter, so reproduced exactly for degree ``n >= 2``.
    """
    L_u, L_v = (_positive(s, "saddle size") for s in _pair(size, "size"))
    h = float(height)
    if not np.isfinite(h):
        raise InputError(f"saddle height must be finite, got {height!r}")
    kinds = _knot_kinds(knots)
    bu, bv = _bases(cells, degree, kinds, (L_u, L_v))

    def f(u: NDArray[np.float64], v: NDArray[np.float64]) -> NDArray[np.float64]:
        xi, eta = 2 * u / L_u - 1, 2 * v / L_v - 1
        return np.stack([u - L_u / 2, v - L_v / 2, h * (xi**2 - eta**2)], axis=-1)

    return _fitted(f, bu, bv, _check_method(method), "saddle")


def tile(radius: float = 1.0, angle: float = pi / 2, length: float = 2.0,
         cells: int | tuple[int, int] = DEFAULT_CELLS, degree: int = 3,
         knots: str | tuple[str, str] = "open", method: str = "interpolate") -> Surface:
    """A cylindrical roof-tile patch: a circular arc of ``angle`` swept along ``y``.

    ``x(u, v) = (R sin φ, v, R cos φ)`` with ``φ = u/R - angle/2``, on
    ``[0, R·angle] × [0, length]`` (arc length in ``u``, so the parametrisation is an
    isometry). The crest ``φ = 0`` is at ``x = 0, z = R``; ``x_u × x_v`` points outwards
    (away from the axis). ``0 < angle < 2π``.
    """
    R = _positive(radius, "tile radius")
    length = _positive(length, "tile length")
    angle = _positive(angle, "tile angle")
    if angle >= 2 * pi:
        raise InputError(f"tile angle must be in (0, 2π) radians, got {angle!r} "
                         f"(a closed tube is shapes.cylinder)")
    kinds = _knot_kinds(knots)
    bu, bv = _bases(cells, degree, kinds, (R * angle, length))

    def f(u: NDArray[np.float64], v: NDArray[np.float64]) -> NDArray[np.float64]:
        phi = u / R - angle / 2
        return np.stack([R * np.sin(phi), v, R * np.cos(phi)], axis=-1)

    return _fitted(f, bu, bv, _check_method(method), "tile")


def half_sphere(radius: float = 1.0, cells: int | tuple[int, int] = CLOSED_CELLS,
                degree: int = 3, knots: str | tuple[str, str] = ("periodic", "open"),
                method: str = "interpolate") -> Surface:
    """The upper half of a sphere, longitude ``u`` by latitude ``v``, rim at ``v = 0``.

    ``x(u, v) = R (cos θ cos φ, cos θ sin φ, sin θ)`` with longitude ``φ = u/R`` and
    latitude ``θ = v/R``, on ``[0, 2πR] × [0, πR/2]`` (arc lengths along the equator and a
    meridian). The edge ``v = 0`` (``"v0"``) is the rim, the equator ``z = 0``; the edge
    ``v = πR/2`` (``"v1"``) is the pole, a degenerate edge where all control points of the
    last row coincide (open knots in ``v``) and ``x_u = 0``. ``x_u × x_v`` points outwards.

    ``u`` is closed: knots default to ``("periodic", "open")``; ``"open"`` or ``"uniform"``
    in ``u`` are allowed too (the surface then has a seam at ``u = 0`` that is only
    continuous). Default ``cells = (16, 8)``.
    """
    R = _positive(radius, "half sphere radius")
    kinds = _knot_kinds(knots)
    bu, bv = _bases(cells, degree, kinds, (2 * pi * R, pi * R / 2))

    def f(u: NDArray[np.float64], v: NDArray[np.float64]) -> NDArray[np.float64]:
        phi, theta = u / R, v / R
        return R * np.stack([np.cos(theta) * np.cos(phi), np.cos(theta) * np.sin(phi),
                             np.sin(theta)], axis=-1)

    return _fitted(f, bu, bv, _check_method(method), "half_sphere")


def cylinder(radius: float = 1.0, height: float = 2.0,
             cells: int | tuple[int, int] = CLOSED_CELLS, degree: int = 3,
             knots: str | tuple[str, str] | None = None, method: str = "interpolate",
             knots_v: str = "open") -> Surface:
    """A circular cylinder (open tube) around the ``z`` axis, ``u`` around, ``v`` up.

    ``x(u, v) = (R cos(u/R), R sin(u/R), v)`` on ``[0, 2πR] × [0, height]``; ``x_u × x_v``
    points outwards. ``u`` is always periodic: ``knots`` as a single string (or
    ``knots_v``) sets the ``v`` layout, as a pair it must read ``("periodic", ...)``.
    Default ``cells = (16, 8)``.
    """
    R = _positive(radius, "cylinder radius")
    height = _positive(height, "cylinder height")
    if knots is None:
        knots = ("periodic", knots_v)
    elif isinstance(knots, str):
        knots = ("periodic", knots)
    elif _pair(knots, "knots")[0] != "periodic":
        raise InputError(f"a cylinder is periodic around its axis: knots in u must be "
                         f"'periodic', got {knots!r}")
    kinds = _knot_kinds(knots)
    bu, bv = _bases(cells, degree, kinds, (2 * pi * R, height))

    def f(u: NDArray[np.float64], v: NDArray[np.float64]) -> NDArray[np.float64]:
        return np.stack([R * np.cos(u / R), R * np.sin(u / R), v], axis=-1)

    return _fitted(f, bu, bv, _check_method(method), "cylinder")


def torus(R: float = 1.0, r: float = 0.4, cells: int | tuple[int, int] = CLOSED_CELLS,
          degree: int = 3, knots: str | tuple[str, str] = "periodic",
          method: str = "interpolate") -> Surface:
    """A ring torus with centre-line radius ``R`` and tube radius ``r < R``.

    ``x(u, v) = ((R + r cos β) cos α, (R + r cos β) sin α, r sin β)`` with ``α = u/R``,
    ``β = v/r``, on ``[0, 2πR] × [0, 2πr]``; both directions closed, ``x_u × x_v``
    points out of the tube. Knots default to periodic in both directions; default
    ``cells = (16, 8)``.
    """
    R = _positive(R, "torus radius R")
    r = _positive(r, "torus tube radius r")
    if r >= R:
        raise InputError(f"torus tube radius r must be smaller than R (a ring torus), "
                         f"got R={R!r}, r={r!r}")
    kinds = _knot_kinds(knots)
    bu, bv = _bases(cells, degree, kinds, (2 * pi * R, 2 * pi * r))

    def f(u: NDArray[np.float64], v: NDArray[np.float64]) -> NDArray[np.float64]:
        alpha, beta = u / R, v / r
        ring = R + r * np.cos(beta)
        return np.stack([ring * np.cos(alpha), ring * np.sin(alpha), r * np.sin(beta)], axis=-1)

    return _fitted(f, bu, bv, _check_method(method), "torus")
