"""The parametric energy of a trimmed surface: matrices over the trimmed region, the WEB
map as constraint map, and Nitsche's terms for the held trim loops; the loops' conditions,
quadrature and penalty that the intrinsic plate and the shell share with it
(:func:`loop_conditions`, :func:`form_matrices`, :mod:`.energy_forms`).

With the surface's B-splines ``b_k`` (tensor, row-major ``k = i n_v + j``) and the
trimmed quadrature ``(x_q, ω_q)`` of :func:`~splinedeform.trim.quadrature.trim_quadrature`
(knot cells as grid), for every coordinate alike

.. math:: K = Σ_{α} w_α B_αᵀ Ω B_α, \\qquad M = μ B_0ᵀ Ω B_0,

``α ∈ {(1,0), (0,1), (2,0), (1,1), (0,2)}`` with weights ``w10, w01, w20, 2 w11, w02``,
``(B_α)_{qk} = ∂^α b_k(x_q)``, ``Ω = diag ω``: the parametric energy of docs/model.md on
``Ω`` instead of the rectangle. The displacement net is ``d = E d_free``, ``E`` Höllig's
extension (:mod:`splinedeform.trim.web`): inner B-splines are the unknowns, outer ones
follow them, the others stay at rest; so every solver works on ``Eᵀ K E`` and ``Eᵀ M E``
unchanged, and the displaced surface stays a B-spline surface.

**Held loops (Nitsche).** Integration by parts of ``a(d, v)`` gives the boundary term

.. math:: b(d, v) = ∮_Γ g_0(d) v + g_u(d) v_u + g_v(d) v_v \\, ds,

    g_u = w20 d_uu n_u + w11 d_uv n_v,  g_v = w02 d_vv n_v + w11 d_uv n_u,
    g_0 = w10 d_u n_u + w01 d_v n_v − (w20 d_uuu n_u + w11 d_uvv n_u + w11 d_uuv n_v
          + w02 d_vvv n_v)

(``n`` the outward normal). A clamped loop (``d = ∇d = 0``) adds
``−b(d, v) − b(v, d) + γ_0 ∮ d v + γ_1 ∮ ∇d·∇v``; a pinned loop (``d = 0``, the moment
``g·n = 0`` natural) adds ``−b_p(d, v) − b_p(v, d) + γ_0 ∮ d v`` with
``b_p = ∮ g_0(d) v + (g(d)·s)(∇v·s)``, ``s`` the tangent. Both are consistent (the exact
solution satisfies the discrete equations) and symmetric;
``γ_0 = β (w_b / h³ + w_t / h)``, ``γ_1 = β w_b / h`` with ``w_b = max(w20, w11, w02)``,
``w_t = max(w10, w01)``, ``h`` the smaller side of the knot cell at each point of the loop
and ``β =`` :func:`nitsche_penalty` of the larger degree.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable, Mapping

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray

from ..boundary import Constraints, build_constraints, trim_conditions
from ..errors import InputError
from ..material import Material
from ..solvers import rigid
from .cells import Grid, loop_pieces
from .energy_forms import Form, energy_matrix, nitsche_matrix, scalar_mass
from .loops import TrimDomain
from .quadrature import TrimQuadrature, trim_quadrature
from .holed import holed_quadrature, with_edges
from .surface_trim import (extension_knots, holed_rectangle, net_weights_of, surface_degrees,
                           trim_grid)
from .values import surface_values
from .web import live_table, web_basis

NITSCHE_FACTOR = 10.0
"""``β = NITSCHE_FACTOR (n + 1)³`` of the Nitsche penalties: above the trace-inverse
constant of the extended basis of degree ``n`` (bounded however a loop cuts a cell, by
Höllig's extension). On the clamped and pinned disc plates ``K_r`` is positive definite
from about ``β = 300`` for cubics and ``β = 1000`` for quartics; ``10 (n+1)³`` is 640 and
1250."""


def nitsche_penalty(degree: int) -> float:
    """``β = NITSCHE_FACTOR (n + 1)³``."""
    return NITSCHE_FACTOR * (degree + 1) ** 3


#: derivative orders ``(a, b)`` of the stiffness terms and the material weight of each
STIFFNESS_TERMS = (("w10", (1, 0), 1.0), ("w01", (0, 1), 1.0), ("w20", (2, 0), 1.0),
                   ("w11", (1, 1), 2.0), ("w02", (0, 2), 1.0))


def loop_keys(count: int) -> tuple[str, ...]:
    """Boundary keys of ``count`` loops: ``outer``, then ``hole1``, ``hole2``, … in order."""
    return ("outer",) + tuple(f"hole{k}" for k in range(1, count))


def loop_names(domain: TrimDomain) -> tuple[str, ...]:
    """Boundary keys of the loops of ``domain`` (:func:`loop_keys`)."""
    return loop_keys(len(domain.loops))


def quadrature_of(surface: Any) -> TrimQuadrature:
    """The trimmed quadrature of a surface, ``n + 2`` Gauss points per direction (``n`` the
    larger degree; exact for the ``2n`` per variable of the energies on inside cells); kept
    with the surface."""
    key = ("trim quadrature",)
    if key not in surface._cache:
        rule = holed_quadrature if holed_rectangle(surface) else trim_quadrature
        surface._cache[key] = rule(surface.trim, trim_grid(surface),
                                      max(surface_degrees(surface)) + 2)
    return surface._cache[key]


def _points(surface: Any, quad: TrimQuadrature) -> NDArray[np.float64]:
    """Quadrature points in the closed rectangle (cut-cell points on a cell's edge)."""
    (_, lu), (_, lv) = surface.domain
    return np.clip(quad.points, 0.0, [lu, lv])


def project(surface: Any, values: Callable[[NDArray, NDArray], NDArray]
            ) -> NDArray[np.float64]:
    """``F_k = ∫_Ω f b_k = Σ_q ω_q f(x_q) b_k(x_q)``, shape ``(n_u n_v, 3)``; ``values(U, V)``
    gets the points' parameter arrays ``(Q,)`` and returns ``(Q, 3)``."""
    quad = quadrature_of(surface)
    p = _points(surface, quad)
    f = np.asarray(values(p[:, 0], p[:, 1]), dtype=float)
    if f.shape != (len(p), 3):
        raise InputError(f"a load function must return an array of shape (..., 3) matching "
                         f"its parameter arrays {(len(p),)}, got {f.shape}")
    if not np.all(np.isfinite(f)):
        raise InputError("a load function returned non-finite values")
    B = surface_values(surface, p, [(0, 0)])[(0, 0)]
    return np.asarray(B.T @ (quad.weights[:, None] * f))


@dataclass(frozen=True)
class TrimmedSystem:
    """Full matrices over the trimmed region (Nitsche terms included), the WEB constraint
    map, and the dimension of ``null K_r``."""

    constraints: Constraints
    stiffness: sp.csr_matrix
    mass: sp.csr_matrix
    rigid_modes: int | None


def trimmed_system(surface: Any, material: Material, boundary: str | Mapping[str, str],
                   lumped: bool = False, physics: str = "parametric", fixed: Any = None,
                   rest: str = "initial") -> TrimmedSystem:
    """``K``, ``M`` (see the module docstring) and ``d = E d_free`` of a trimmed surface."""
    if physics not in ("parametric", "intrinsic"):
        raise InputError(f"a trimmed surface's plate takes physics 'parametric' or "
                         f"'intrinsic' (its energy over the trimmed region), got {physics!r}; "
                         "the shell is ShellModel")
    grid = trim_grid(surface)
    rectangle = holed_rectangle(surface)
    edges, loops, held = loop_conditions(surface, boundary)
    if held and rest == "none":
        raise InputError("rest = 'none' (the energy of the position itself) is not combined "
                         "with pinned or clamped trim loops yet: Nitsche's terms hold the "
                         "displacement, not the position; use rest = 'initial'")
    bending = max(material.w20, material.w11, material.w02)
    if held and bending and min(surface_degrees(surface)) < 3:
        raise InputError("a pinned or clamped trim loop under bending weights needs degree "
                         f">= 3 (third derivatives in Nitsche's terms), got "
                         f"{surface_degrees(surface)}")
    quad = quadrature_of(surface)
    if physics == "intrinsic":
        from .intrinsic_trimmed import intrinsic_matrices

        K, M = intrinsic_matrices(surface, material, held)
    else:
        K, M = _parametric_matrices(surface, material, quad)
        if held:
            K = K + nitsche_terms(surface, material, grid, held)
    if lumped:
        M = sp.diags(np.asarray(M.sum(axis=1)).ravel())
    mask = None if fixed is None else np.asarray(fixed, dtype=bool)
    if mask is not None:
        try:
            T, free_index = with_edges(surface, edges, quad.classes, mask)
        except InputError as exc:       # marked: the mask is the cause (a body names its face)
            exc.fixed_points = True  # type: ignore[attr-defined]
            raise
    elif rectangle:
        T, free_index = with_edges(surface, edges, quad.classes, mask)
    else:
        web = web_basis(quad.classes, surface_degrees(surface), knots=extension_knots(surface),
                        weights=net_weights_of(surface))
        T, free_index = web.extension.tocsr(), np.flatnonzero(web.inner.ravel())
    pinned_points = bool(mask is not None and held_live(surface, quad.classes, mask).any())
    constraints = Constraints(T, None, None, free_index, {**edges, **loops}, pinned_points)
    return TrimmedSystem(constraints, ((K + K.T) * 0.5).tocsr(), sp.csr_matrix(M),
                         _rigid_count(surface, material, bool(held) or pinned_points
                                      or set(edges.values()) != {"free"}, physics))


def held_live(surface: Any, classes: NDArray[np.int64], mask: Any) -> NDArray[np.bool_]:
    """The points of a mask of fixed control points (``(n_u, n_v)``, True: at rest) whose
    B-splines meet the region (inner or outer, :func:`~.web.live_table`): those it holds.
    A point whose B-spline is dead (its support outside the region) is at rest whatever
    the mask says, and holds nothing."""
    live = live_table(classes, surface_degrees(surface))
    return np.asarray(mask, dtype=bool).reshape(live.shape) & live


def _parametric_matrices(surface: Any, material: Material, quad: TrimQuadrature
                         ) -> tuple[sp.csr_matrix, sp.csr_matrix]:
    """``K = Σ_α w_α B_αᵀ Ω B_α``, ``M = μ B_0ᵀ Ω B_0`` (module docstring)."""
    orders = [(0, 0)] + [ab for key, ab, _ in STIFFNESS_TERMS if getattr(material, key)]
    B = surface_values(surface, _points(surface, quad), orders)
    om = sp.diags(quad.weights)
    K = sp.csr_matrix((B[(0, 0)].shape[1],) * 2)
    for key, ab, factor in STIFFNESS_TERMS:
        weight = factor * getattr(material, key)
        if weight:
            K = K + weight * (B[ab].T @ om @ B[ab])
    return K, material.mass * (B[(0, 0)].T @ om @ B[(0, 0)])


def loop_conditions(surface: Any, boundary: str | Mapping[str, str]
                    ) -> tuple[dict[str, str], dict[str, str], dict[int, str | tuple[str, ...]]]:
    """The rectangle's edges' and the loops' presets
    (:func:`~splinedeform.boundary.trim_conditions`) and the held loops: ``{k: preset}``
    of loop ``k``, or the tuple of its trim edges' presets, for those not wholly free."""
    domain: TrimDomain = surface.trim
    names = loop_names(domain)
    counts = {name: domain.edge_count(k) for k, name in enumerate(names)}
    edges, loops = trim_conditions(boundary, names, holed_rectangle(surface), counts)
    held = {k: v for k, v in enumerate(_loop_presets(loops, names, counts))
            if set(np.atleast_1d(v)) != {"free"}}
    return edges, loops, held


def form_nitsche(surface: Any, form: Form, held: Mapping[int, str | tuple[str, ...]]
                 ) -> sp.csr_matrix:
    """Nitsche's terms of an energy :class:`~.energy_forms.Form` on the ``held`` loops
    (:func:`~.energy_forms.nitsche_matrix`; points of :func:`held_points`, ``h`` of
    :func:`_cell_size`, ``β`` of :func:`nitsche_penalty`)."""
    grid = trim_grid(surface)
    p, ds, n, s, preset = held_points(surface, grid, held)
    on = preset != "free"
    return nitsche_matrix(surface, form, p[on], ds[on], n[on], s[on], preset[on] == "clamped",
                          _cell_size(grid, p[on]), nitsche_penalty(max(surface_degrees(surface))))


def form_matrices(surface: Any, form: Form, held: Mapping[int, str | tuple[str, ...]]
                  ) -> tuple[sp.csr_matrix, sp.csr_matrix]:
    """``K`` of an energy :class:`~.energy_forms.Form` over the trimmed region (with
    :func:`form_nitsche` of the ``held`` loops) and the scalar mass
    ``ρ ∫_Ω b_k b_l √g du dv`` of its density."""
    quad = quadrature_of(surface)
    points = _points(surface, quad)
    K = energy_matrix(surface, form, points, quad.weights)
    if held:
        K = K + form_nitsche(surface, form, held)
    return K.tocsr(), scalar_mass(surface, points, quad.weights, form.density)


def _rigid_count(surface: Any, material: Material, holds: bool, physics: str = "parametric"
                 ) -> int | None:
    """``dim null K_r``: 0 where loops, edges or fixed points hold the surface (Nitsche's
    penalty, the constraints); else the energy's polynomials, which the extension
    reproduces; on a rational net, or for the intrinsic energy (``|∇_S d|² = 0`` only for
    constants), the constants alone under tension in u and v (``Σ R_k = 1``), and None (not
    known from the structure) without it."""
    if holds:
        return 0
    if physics == "intrinsic":
        return 1 if material.w10 else None
    if net_weights_of(surface) is not None:
        return 1 if material.w10 and material.w01 else None
    bases = (surface.basis_u, surface.basis_v)
    return int(rigid.rigid_count(rigid.parametric_terms(material), *bases,
                                 build_constraints(*bases, "free")))


def _loop_presets(presets: Mapping[str, str], names: tuple[str, ...],
                  counts: Mapping[str, int]) -> list[str | tuple[str, ...]]:
    """Each loop's preset, or its trim edges' (``name.k``, else the loop's) where some
    edge of it is named."""
    out: list[str | tuple[str, ...]] = []
    for name in names:
        keys = [f"{name}.{k}" for k in range(counts[name])]
        if any(key in presets for key in keys):
            out.append(tuple(presets.get(key, presets[name]) for key in keys))
        else:
            out.append(presets[name])
    return out


def loop_quadrature(domain: TrimDomain, grid: Grid, order: int, loops: tuple | None = None
                    ) -> tuple[NDArray[np.float64], ...]:
    """Gauss points along every loop piece (of ``loops``, default all): points ``(P, 2)``,
    arc-length weights ``(P,)``, outward unit normals ``(P, 2)``, unit tangents ``(P, 2)``
    (with ``Ω`` on their left), the loop index ``(P,)`` among those split and the trim edge
    ``(P,)`` of each point in its loop (:attr:`TrimDomain.edges`; 0 where a loop is one)."""
    xi, om = np.polynomial.legendre.leggauss(order)
    pieces = loop_pieces(domain, grid, loops)
    half = 0.5 * (pieces.hi - pieces.lo)
    t = 0.5 * (pieces.lo + pieces.hi)[:, None] + half[:, None] * xi
    point, tangent = pieces.evaluate(t)
    speed = np.hypot(tangent[..., 0], tangent[..., 1])
    run = np.sign(half)[:, None, None] * tangent / speed[..., None]
    ds = np.abs(half)[:, None] * om * speed
    normal = np.stack([run[..., 1], -run[..., 0]], axis=-1)
    loop = np.broadcast_to(pieces.loop[:, None], ds.shape)
    labels = [None] * len(domain.loops) if loops is None else [
        domain.edges[next(k for k, own in enumerate(domain.loops) if own is given)]
        for given in loops]
    edge = np.zeros(len(pieces.loop), int)
    for k, own in enumerate(labels):          # a loop over the loops, not the points
        if own is not None:
            on = pieces.loop == k
            edge[on] = np.asarray(own)[pieces.span[on]]
    edge = np.broadcast_to(edge[:, None], ds.shape)
    return (point.reshape(-1, 2), ds.ravel(), normal.reshape(-1, 2), run.reshape(-1, 2),
            loop.ravel(), edge.ravel())


def held_points(surface: Any, grid: Grid, held: Mapping[int, str | tuple[str, ...]]
                ) -> tuple[NDArray[np.float64], ...]:
    """Gauss points on the trim loops (:func:`loop_quadrature`, ``n + 2`` per piece; not
    the rectangle of a holed one) with the preset of each: ``held[k]`` that of loop ``k``,
    or a tuple of those of its trim edges. Points ``(P, 2)`` in the closed rectangle,
    weights, normals, tangents, presets ``(P,)``."""
    domain = surface.trim
    first = 1 if holed_rectangle(surface) else 0       # the rectangle's edges are no loop
    p, ds, n, s, loop, edge = loop_quadrature(domain, grid, max(surface_degrees(surface)) + 2,
                                              domain.loops[first:])
    loop = loop + first
    preset = np.full(len(loop), "free", dtype=object)
    for k, value in held.items():             # a loop over the loops, not the points
        on = loop == k
        preset[on] = value if isinstance(value, str) else np.asarray(value, object)[edge[on]]
    (_, lu), (_, lv) = surface.domain
    return np.clip(p, 0.0, [lu, lv]), ds, n, s, preset


def nitsche_terms(surface: Any, material: Material, grid: Grid,
                  held: Mapping[int, str | tuple[str, ...]]) -> sp.csr_matrix:
    """Nitsche's symmetric terms and penalties of the held loops (module docstring):
    ``held[k]`` the preset of loop ``k``, or a tuple of the presets of its trim edges."""
    m = material
    p, ds, n, s, preset = held_points(surface, grid, held)
    orders = [(0, 0), (1, 0), (0, 1), (2, 0), (1, 1), (0, 2), (3, 0), (2, 1), (1, 2), (0, 3)]
    if not (m.w20 or m.w11 or m.w02):
        orders = orders[:3]
    B = surface_values(surface, p, orders)
    zero = sp.csr_matrix(B[(0, 0)].shape)
    D = lambda ab: B.get(ab, zero)  # noqa: E731
    nu, nv, su, sv = (sp.diags(x) for x in (n[:, 0], n[:, 1], s[:, 0], s[:, 1]))
    g0 = (m.w10 * nu @ D((1, 0)) + m.w01 * nv @ D((0, 1))
          - (m.w20 * nu @ D((3, 0)) + m.w11 * (nu @ D((1, 2)) + nv @ D((2, 1)))
             + m.w02 * nv @ D((0, 3))))
    gu = m.w20 * nu @ D((2, 0)) + m.w11 * nv @ D((1, 1))
    gv = m.w02 * nv @ D((0, 2)) + m.w11 * nu @ D((1, 1))
    h = _cell_size(grid, p)
    bending, tension = max(m.w20, m.w11, m.w02), max(m.w10, m.w01)
    beta = nitsche_penalty(max(surface_degrees(surface)))
    gamma0 = sp.diags(beta * (bending / h ** 3 + tension / h))
    gamma1 = sp.diags(beta * bending / h)
    K = sp.csr_matrix((B[(0, 0)].shape[1],) * 2)
    for kind in ("pinned", "clamped"):
        on = preset == kind
        if not on.any():
            continue
        w = sp.diags(np.where(on, ds, 0.0))
        b0, bu, bv = B[(0, 0)], B[(1, 0)], B[(0, 1)]
        if kind == "clamped":
            term = b0.T @ w @ g0 + bu.T @ w @ gu + bv.T @ w @ gv
            penalty = (b0.T @ w @ gamma0 @ b0
                       + bu.T @ w @ gamma1 @ bu + bv.T @ w @ gamma1 @ bv)
        else:
            bs = su @ bu + sv @ bv
            term = b0.T @ w @ g0 + bs.T @ w @ (su @ gu + sv @ gv)
            penalty = b0.T @ w @ gamma0 @ b0
        K = K - term - term.T + penalty
    return K.tocsr()


def _cell_size(grid: Grid, p: NDArray[np.float64]) -> NDArray[np.float64]:
    """``h`` at each point ``(P, 2)``: the smaller side of the knot cell holding it."""
    sides = []
    for axis in (0, 1):
        lines = grid.lines(axis)
        cell = np.clip(grid.cell_of(p[:, axis], axis), 0, len(lines) - 2)
        sides.append(np.diff(lines)[cell])
    return np.minimum(*sides)
