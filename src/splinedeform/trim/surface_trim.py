"""A trim region checked against the surface it trims."""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..basis import BSplineBasis
from ..errors import InputError
from .cells import SIDE_TOL, Grid
from .loops import Loop, PolygonLoop, TrimDomain


def loop_outside(surface: Any, loop: Loop) -> str | None:
    """What is wrong when ``loop`` leaves the parameter rectangle ``[0, L_u] × [0, L_v]``
    of ``surface`` by more than :data:`SIDE_TOL` of its diagonal (a loop may run
    along its sides, as most outer loops of CAD faces do: its pieces there lie in the
    cells beside them, :func:`~splinedeform.trim.cells.loop_pieces`); None when it does
    not. A spline loop is bounded by its control points."""
    (_, lu), (_, lv) = surface.domain
    tol = SIDE_TOL * float(np.hypot(lu, lv))
    low, high = (np.asarray(b, dtype=float) for b in loop.bounds())
    if np.any(low < -tol) or high[0] > lu + tol or high[1] > lv + tol:
        return (f"reaches outside the parameter domain [0, {lu:g}] × [0, {lv:g}] of the "
                f"surface: it spans [{low[0]:g}, {high[0]:g}] × [{low[1]:g}, {high[1]:g}]")
    return None


def trim_grid(surface: Any) -> Grid:
    """The knot cells of a surface that can be trimmed: ``uniform`` or ``open`` knots (equal
    cells), or a general clamped knot vector with simple interior knots (cells between its
    breakpoints), in each direction; the degrees may differ."""
    from ..knots import KnotVectorBasis

    bases = tuple(polynomial_basis(b) for b in (surface.basis_u, surface.basis_v))
    equal = True
    for name, basis in zip("uv", bases):
        needs = (f"a trimmed surface ({getattr(surface, 'name', None)!r}) needs in {name} "
                 "uniform or open knots or a clamped knot vector with simple interior knots")
        if isinstance(basis, KnotVectorBasis):
            problem = _knot_problem(basis)
            if problem:
                raise InputError(f"{needs}: {problem}")
            equal = False
        elif not isinstance(basis, BSplineBasis) or basis.kind not in ("uniform", "open"):
            kind = getattr(basis, "kind", type(basis).__name__)
            advice = (": a closed (periodic) direction is not trimmed yet; make the surface "
                      "with open knots in it (shapes …(knots='open'), its seam an edge of "
                      "the rectangle), or take the whole surface (a scenario's "
                      "surface.trimmed = false)") if kind == "periodic" else ""
            raise InputError(f"{needs}, got {kind!r}{advice}")
    if equal:
        return Grid((bases[0].cells, bases[1].cells), (bases[0].length, bases[1].length))
    return Grid.of_breaks(*(_breaks(b) for b in bases))


def polynomial_basis(basis: Any) -> Any:
    """The B-splines under a per-direction rational basis (the basis itself otherwise)."""
    from ..knots import RationalBasis

    return basis.basis if isinstance(basis, RationalBasis) else basis


def net_weights_of(surface: Any) -> NDArray[np.float64] | None:
    """The NURBS weights of the net, flat (``a_k b_l`` of per-direction rational bases);
    None for a polynomial surface."""
    from ..knots import RationalBasis

    if surface.net_weights is not None:
        return np.asarray(surface.net_weights, dtype=float).ravel()
    factors = [b.weights if isinstance(b, RationalBasis) else np.ones(b.size)
               for b in (surface.basis_u, surface.basis_v)]
    if not any(isinstance(b, RationalBasis) for b in (surface.basis_u, surface.basis_v)):
        return None
    return np.outer(*factors).ravel()


def _breaks(basis: Any) -> NDArray[np.float64]:
    """The cells' lines of a basis: its breakpoints, or equal cells."""
    if hasattr(basis, "breaks"):
        return np.asarray(basis.breaks, dtype=float)
    return np.arange(basis.cells + 1) * (basis.length / basis.cells)


def _knot_problem(basis: Any) -> str | None:
    """What keeps a general knot vector from a trim (None when it can take one): the
    B-spline ``k`` must live on cells ``k - n .. k``, so the ends are clamped (``n + 1``
    equal knots, the first 0) and interior knots simple."""
    t, n = np.asarray(basis.knots, dtype=float), basis.degree
    breaks = np.asarray(basis.breaks, dtype=float)
    if breaks[0] != 0.0 or np.any(t[:n + 1] != t[0]) or np.any(t[-n - 1:] != t[-1]):
        return f"its knots {t.tolist()} are not clamped from 0"
    if len(t) != len(breaks) + 2 * n:
        inner = t[n + 1:len(t) - n - 1]
        repeated = sorted({float(x) for x in inner if np.count_nonzero(inner == x) > 1})
        return (f"its knots {t.tolist()} repeat the interior knot(s) {repeated} (C0 or "
                "weaker lines), across which a trimmed surface is not simulated yet; split "
                "the surface at those lines into patches of a Body, or take the whole "
                "surface (a scenario's surface.trimmed = false); inserting knots "
                "(surface.refine) does not remove a repeated one")
    return None


def extension_knots(surface: Any) -> tuple[NDArray[np.float64], NDArray[np.float64]] | None:
    """The knot vectors Höllig's extension of ``surface`` needs
    (:func:`~splinedeform.trim.web.web_basis`): None where both directions have uniform
    knots (Lagrange interpolation in the index is then exact)."""
    bases = tuple(polynomial_basis(b) for b in (surface.basis_u, surface.basis_v))
    if all(getattr(b, "kind", None) == "uniform" for b in bases):
        return None
    return tuple(np.asarray(b.knots, dtype=float) for b in bases)  # type: ignore[return-value]


def surface_degrees(surface: Any) -> tuple[int, int]:
    """``(n_u, n_v)`` of a surface."""
    return surface.basis_u.degree, surface.basis_v.degree


def whole_rectangle(surface: Any, loop: Loop) -> bool:
    """Whether ``loop`` is the parameter rectangle itself: a polygon through its four
    corners with every vertex on its sides (collinear midpoints of a CAD face's edges
    allowed), both to :data:`SIDE_TOL` of the rectangle's diagonal. It is the outer
    loop of a rectangle with holes, whose edges are the rectangle's edges ``u0``, ``u1``,
    ``v0``, ``v1``."""
    if not isinstance(loop, PolygonLoop):
        return False
    (_, lu), (_, lv) = surface.domain
    tol = SIDE_TOL * float(np.hypot(lu, lv))
    corners = np.array([[0.0, 0.0], [lu, 0.0], [lu, lv], [0.0, lv]])
    gap = np.abs(loop.vertices[:, None, :] - corners[None]).max(axis=-1)
    u, v = loop.vertices.T
    off_side = np.minimum(np.minimum(np.abs(u), np.abs(u - lu)),
                          np.minimum(np.abs(v), np.abs(v - lv)))
    inside_box = ((u >= -tol) & (u <= lu + tol) & (v >= -tol) & (v <= lv + tol))
    area = abs(loop.signed_area)
    return bool(np.all(gap.min(axis=0) <= tol) and np.all(off_side <= tol)
                and np.all(inside_box) and abs(area - lu * lv) <= tol * (lu + lv))


def holed_rectangle(surface: Any) -> bool:
    """Whether the trim of ``surface`` is its rectangle less holes (:func:`whole_rectangle`)."""
    return surface.trim is not None and whole_rectangle(surface, surface.trim.outer)


def region_contains(surface: Any, p: Any) -> NDArray[np.bool_]:
    """Point-in-region test of the trimmed region, the rectangle's edges inside when it is
    the outer loop (there the even–odd test of the outer polygon is ambiguous)."""
    if not holed_rectangle(surface):
        return surface.trim.contains(p)
    p = np.asarray(p, dtype=float)
    inside = np.ones(p.shape[:-1], dtype=bool)
    for hole in surface.trim.holes:
        inside &= ~hole.encloses(p)
    return inside


def checked_trim(surface: Any, domain: Any) -> TrimDomain:
    """``domain`` if it is a :class:`TrimDomain` whose loops all lie inside the parameter
    rectangle of ``surface`` (:func:`loop_outside`), on a surface that can be trimmed
    (:func:`trim_grid`)."""
    trim_grid(surface)
    if not isinstance(domain, TrimDomain):
        raise InputError(f"a surface's trim must be a splinedeform.trim.TrimDomain, got "
                         f"{type(domain).__name__}")
    for k, loop in enumerate(domain.loops):
        if k == 0 and whole_rectangle(surface, loop):
            continue
        problem = loop_outside(surface, loop)
        if problem:
            raise InputError(f"trim loop {'the outer loop' if k == 0 else f'hole {k}'} "
                             f"{problem}")
    return domain


def equal_cell_form(surface: Any) -> Any:
    """``surface`` with each direction whose general knot vector is clamped with equal
    cells (to :data:`SIDE_TOL` of its length; a CAD face refined by ``refine`` and
    ``elevate``) given as the same B-splines in the ``open`` layout, which a trim needs
    (:func:`trim_grid`); other directions, and the control net, unchanged."""
    from dataclasses import replace

    from ..knots import KnotVectorBasis

    bases = []
    for basis in (surface.basis_u, surface.basis_v):
        if isinstance(basis, KnotVectorBasis):
            cells, length = len(basis.breaks) - 1, float(basis.breaks[-1])
            open_basis = BSplineBasis(basis.degree, cells, length, "open")
            if (basis.breaks[0] == 0.0 and len(basis.knots) == len(open_basis.knots)
                    and np.abs(basis.knots - open_basis.knots).max() <= SIDE_TOL * length):
                basis = open_basis
        bases.append(basis)
    if bases[0] is surface.basis_u and bases[1] is surface.basis_v:
        return surface
    return replace(surface, basis_u=bases[0], basis_v=bases[1])
