"""Initial surfaces: a control net fitted to a map or a point grid, and built-in shapes.

A parametric map ``f(u, v) -> (..., 3)`` becomes a control net by interpolation, L2
projection or a local quasi-interpolant (:mod:`splinedeform.fit`, separable, one 1-D
operator per direction); a grid of points by least squares (:mod:`splinedeform.point_grid`).

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

from math import pi

import numpy as np
from numpy.typing import NDArray

from .basis import BSplineBasis
from .errors import InputError
from .fit import (  # noqa: F401 (FIT_METHODS, POINT_METHODS and the fitting functions: public here)
    CLOSED_CELLS, DEFAULT_CELLS, FIT_METHODS, POINT_METHODS, Domain, Map, _bases, _check_method,
    _domain, _fitted, _knot_kinds, _pair, _positive, error_samples, fit_control_points,
    fit_error, quasi_weights)
from .point_grid import chord_lengths, from_points  # noqa: F401 (public here)
from .surface import Surface

__all__ = ["FIT_METHODS", "chord_lengths", "cylinder", "error_samples", "fit_control_points", "fit_error",
           "from_function", "from_points", "half_sphere", "plane", "quasi_weights", "saddle",
           "tile", "torus"]


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


# -- built-in shapes ------------------------------------------------------------------------
def plane(size: float | tuple[float, float] = (1.0, 1.0),
          cells: int | tuple[int, int] = DEFAULT_CELLS, degree: int = 3,
          knots: str | tuple[str, str] = "open", method: str = "interpolate") -> Surface:
    """The flat rectangle ``x(u, v) = (u, v, 0)`` on ``[0, L_u] × [0, L_v]``.

    Parameters
    ----------
    size : float or (L_u, L_v)
        Side lengths; the parameter domain is the rectangle itself.

    Every method reproduces it exactly for any degree ``n >= 1`` (linear precision), so
    on open and uniform knots no fit is made: the net is the knot averages
    ``P_ij = (ξ_i, η_j, 0)``, ``ξ_i = (t_{i+1} + … + t_{i+n}) / n``, for which
    ``Σ_i ξ_i B_i(u) = u`` on ``[0, L_u]`` (Marsden's identity), and ``fit_error`` is 0
    (rounding of the averages aside). ``x_u × x_v = (0, 0, 1)``.
    """
    L_u, L_v = (_positive(s, "plane size") for s in _pair(size, "size"))
    kinds = _knot_kinds(knots)
    bu, bv = _bases(cells, degree, kinds, (L_u, L_v))
    method = _check_method(method)
    if not (bu.periodic or bv.periodic):
        xi, eta = _knot_averages(bu), _knot_averages(bv)
        P = np.zeros((xi.size, eta.size, 3))
        P[:, :, 0], P[:, :, 1] = xi[:, None], eta[None, :]
        return Surface(P, bu, bv, fit_error=0.0, name="plane")

    def f(u: NDArray[np.float64], v: NDArray[np.float64]) -> NDArray[np.float64]:
        return np.stack([u, v, np.zeros_like(u)], axis=-1)

    return _fitted(f, bu, bv, method, "plane")       # periodic: refused as not closed


def _knot_averages(basis: BSplineBasis) -> NDArray[np.float64]:
    """``ξ_i = (t_{i+1} + … + t_{i+n}) / n`` of each function of a non-periodic basis (for
    uniform knots some lie outside ``[0, L]``: the true averages, not the clamped Greville
    points of :meth:`~splinedeform.basis.BSplineBasis.greville`)."""
    n = basis.degree
    window = np.lib.stride_tricks.sliding_window_view(basis.knots[1:-1], n)[:basis.size]
    return window.mean(axis=1)


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
