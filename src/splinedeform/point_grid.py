"""Fitting a control net to a grid of points sampled evenly on the parameter domain.

Point ``grid[i, j]`` is taken as ``x(u_i, v_j)``; the control net is the (weighted) least
squares solution, one 1-D operator per direction (:func:`from_points`). The parameter
domain defaults to the grid's mean chord lengths (:func:`chord_lengths`), so that a grid
sampled evenly in arc length gets a parametrisation close to isometric and the parametric
energy (the paper's) approximates the one measured on the surface. Re-exported from
:mod:`splinedeform.shapes`.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .basis import BSplineBasis
from .errors import InputError
from .fit import (DEFAULT_CELLS, POINT_METHODS, Domain, _apply_both, _bases, _check_method,
                  _domain, _knot_kinds)
from .surface import Surface


def from_points(grid: ArrayLike, cells: int | tuple[int, int] = DEFAULT_CELLS, degree: int = 3,
                knots: str | tuple[str, str] = "open", method: str = "interpolate",
                domain: Domain | None = None,
                name: str | None = None) -> Surface:
    """Fit a spline surface to a grid of points sampled evenly on the parameter domain.

    Point ``grid[i, j]`` is taken as ``x(u_i, v_j)`` with ``u_i = i L_u / (N_u - 1)``
    (``L_u = b - a`` of ``domain``; the surface's parameters start at 0). In a periodic
    direction the samples are ``u_i = i L_u / N_u`` unless the last row repeats the first
    (a closed grid), in which case the repeat is dropped.

    Parameters
    ----------
    grid : array_like, shape ``(N_u, N_v, 3)``
    cells, degree, knots, name
        As in :func:`from_function`.
    domain : ((a, b), (c, d)), optional
        Parameter rectangle; only its lengths ``L_u = b - a``, ``L_v = d - c`` matter. Default:
        the grid's mean chord lengths (:func:`chord_lengths`), ``L_u = (1/N_v) Σ_j Σ_i
        |X_{i+1,j} - X_ij|`` and likewise ``L_v``. On a plane sampled evenly this is the
        arc-length parametrisation, where the parametric energy *is* the physical one; with
        ``((0, 1), (0, 1))`` a 2 × 3 panel would be squeezed into the unit square and its
        parametric energy (tension and bending measured in ``u, v``) would be far off.
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
    if domain is None:
        lengths = chord_lengths(X, (kinds[0] == "periodic", kinds[1] == "periodic"))
    else:
        (a, b), (c, d) = _domain(domain)
        lengths = (b - a, d - c)
    bu, bv = _bases(cells, degree, kinds, lengths)
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


def chord_lengths(X: NDArray[np.float64], periodic: tuple[bool, bool] = (False, False)
                  ) -> tuple[float, float]:
    """Mean chord lengths ``(L_u, L_v)`` of a point grid ``X`` of shape ``(N_u, N_v, 3)``.

    ``L_u = (1/N_v) Σ_j Σ_i |X_{i+1,j} - X_ij|``: the length of the polygon through each
    column of points (u direction), averaged over the columns; likewise ``L_v`` over the
    rows. A periodic direction adds the closing chord ``|X_{0,j} - X_{N_u-1,j}|`` (zero when
    the grid repeats its first row). A grid whose points all coincide in a direction gets
    length 1 there (and is refused by the fit, which names the coincident points).
    """
    out = []
    for axis, closed in ((0, periodic[0]), (1, periodic[1])):
        steps = np.linalg.norm(np.diff(X, axis=axis), axis=-1).sum(axis=axis)
        if closed:
            steps = steps + np.linalg.norm(np.take(X, 0, axis=axis) - np.take(X, -1, axis=axis),
                                           axis=-1)
        out.append(float(steps.mean()) or 1.0)
    return out[0], out[1]


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
