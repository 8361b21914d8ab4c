"""Quadratic energies with variable coefficients over a trimmed region, and their Nitsche
terms on held trim loops, in the surface's parameters.

An energy density of ``C`` displacement components (1 for the plate's shared coordinate,
3 for the shell) that is quadratic in the parameter derivatives ``D^s d`` of the slots
``s ∈ S = (u, v, uu, uv, vv)`` is written through ``R`` strain rows and a symmetric
constitutive matrix per point (:class:`Form`)::

    e_i(d) = Σ_{c,s} V_{i c s} D^s d_c,         a(d, v) = ∫_Ω e(d)ᵀ C e(v) du dv

(``C`` holds the area element ``√g``), so ``a(d, v) = ∫ Σ_t σ_t(d)·D^t v`` with the
conjugate ``σ_t(d) = Σ_s A_ts D^s d``, ``A_ts = Σ_ij V_{i·t} C_ij V_{j·s}ᵀ`` (``C × C``).
Green's theorem in ``(u, v)`` (outward normal ``n``, parameter arc length ``ds``, the mixed
slot split evenly between its two orders) gives the boundary form

.. math:: a(d, v) = ∫_Ω (L d)·v + ∮_Γ g_0(d)·v + g_u(d)·v_u + g_v(d)·v_v \\, ds,

    g_u = σ_uu n_u + ½ σ_uv n_v,   g_v = σ_vv n_v + ½ σ_uv n_u,
    g_0 = σ_u n_u + σ_v n_v − (∂_u σ_uu n_u + ½(∂_u σ_uv n_v + ∂_v σ_uv n_u) + ∂_v σ_vv n_v),

the parametric plate's terms (:mod:`.model_matrices`) with the coefficients' derivatives
``∂_γ A`` added. These come from the surface's third derivatives: ``A`` is a function of
``x_,α`` and ``x_,αβ``, which move along ``γ`` as ``x_,αγ`` and ``x_,αβγ``; ``∂_γ A`` is the
central difference of ``A`` along that line, Richardson-extrapolated (error ``O(h⁴)``,
``h`` :data:`STEP` of the knot cell; no knot line is crossed, the derivatives are the
point's own).

Held loops (Nitsche): clamped ``−b(d, v) − b(v, d) + γ_0 ∮ d·v + γ_1 ∮ Σ_m ρ_m(d) ρ_m(v)``
with ``b`` the boundary form and ``ρ_m`` the rotations the physics holds
(:attr:`Form.rotation`); pinned the same with ``b_p = ∮ g_0·v + (g·s)(∂_s v)`` and no
rotation penalty. ``γ_0 = β (w_b/h³ + w_t/h)``, ``γ_1 = β w_b/h`` with ``w_t`` the largest
diagonal entry of the first-order block of ``A`` at the point, ``w_b`` of its second-order
block (``A_{uv,uv}`` halved, the mixed slot counting twice in ``|∇²d|²``): on a flat
unit-speed plate these are the parametric plate's ``max(w10, w01)`` and
``max(w20, w11, w02)``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray

from .values import surface_values

Array = NDArray[np.float64]
#: parameter derivative orders of the slots ``u, v, uu, uv, vv``
SLOTS = ((1, 0), (0, 1), (2, 0), (1, 1), (0, 2))
#: the finite-difference step of ``∂_γ A``, as a fraction of the knot cell
STEP = 1e-3


@dataclass(frozen=True)
class Geometry:
    """The initial surface at scattered points: ``a (P, 2, 3)`` the covariant basis,
    ``a2 (P, 3, 3)`` ``x_,11, x_,12, x_,22``, ``sqrt_g (P,)``, ``g_inv (P, 2, 2)``, the unit
    normal ``a3 (P, 3)`` and the Christoffel symbols ``gamma (P, 2, 3)`` (``Γ^γ_{11, 12, 22}``)."""

    a: Array
    a2: Array
    sqrt_g: Array
    g_inv: Array
    a3: Array
    gamma: Array


def geometry(a: Array, a2: Array) -> Geometry:
    """:class:`Geometry` from ``x_,α`` and ``x_,αβ``: ``g_αβ = a_α·a_β``,
    ``√g = |a_1 × a_2|``, ``Γ^γ_αβ = g^γδ a_δ·a_αβ``."""
    g = np.einsum("pic,pjc->pij", a, a)
    det = g[:, 0, 0] * g[:, 1, 1] - g[:, 0, 1] ** 2
    g_inv = np.stack([np.stack([g[:, 1, 1], -g[:, 0, 1]], -1),
                      np.stack([-g[:, 1, 0], g[:, 0, 0]], -1)], -2) / det[:, None, None]
    cross = np.cross(a[:, 0], a[:, 1])
    sqrt_g = np.linalg.norm(cross, axis=-1)
    contra = np.einsum("pij,pjc->pic", g_inv, a)
    gamma = np.einsum("pic,pkc->pik", contra, a2)
    return Geometry(a, a2, sqrt_g, g_inv, cross / sqrt_g[:, None], gamma)


@dataclass(frozen=True)
class Form:
    """A quadratic energy density (module docstring).

    ``strains(geometry) -> (V (P, R, C, 5), C (P, R, R))``; ``rotation(geometry, n)``
    ``-> (P, M, C, 2)``: the rotations ``ρ_m(d) = Σ_{c,β} ρ_{mcβ} ∂_β d_c`` a clamped loop
    holds; ``density`` the mass per unit area.
    """

    components: int
    strains: Callable[[Geometry], tuple[Array, Array]]
    rotation: Callable[[Geometry, Array], Array]
    density: float


def gradient_rotation(geo: Geometry, n: Array) -> Array:
    """A clamped scalar field holds its whole gradient: ``ρ = (∂_u d, ∂_v d)``."""
    return np.broadcast_to(np.eye(2)[None, :, None, :], (len(n), 2, 1, 2))


@dataclass(frozen=True)
class Local:
    """The ``m`` basis functions not vanishing at each of ``P`` points: ``cols (P, m)`` and
    ``values[(a, b)] (P, m)``."""

    cols: NDArray[np.int64]
    values: dict[tuple[int, int], Array]


def local_values(surface: Any, p: Array, orders: list[tuple[int, int]]) -> Local:
    """:func:`~.values.surface_values` read back per point (every order has the same
    ``m`` columns per row)."""
    B = surface_values(surface, p, orders)
    first = B[orders[0]]
    m = first.indptr[1] - first.indptr[0] if len(p) else 0
    return Local(first.indices.reshape(len(p), m),
                 {ab: B[ab].data.reshape(len(p), m) for ab in orders})


def surface_geometry(surface: Any, p: Array, third: bool = False
                     ) -> tuple[Geometry, dict[tuple[int, int], Array]]:
    """The :class:`Geometry` at ``p (P, 2)`` and, with ``third``, ``x_,uuu … x_,vvv``."""
    orders = list(SLOTS) + ([(3, 0), (2, 1), (1, 2), (0, 3)] if third else [])
    B = surface_values(surface, p, orders)
    P = surface.control_points.reshape(-1, 3)
    x = {ab: np.asarray(B[ab] @ P) for ab in orders}
    geo = geometry(np.stack([x[1, 0], x[0, 1]], 1), np.stack([x[2, 0], x[1, 1], x[0, 2]], 1))
    return geo, x


def _scatter(cols: NDArray[np.int64], blocks: Array, C: int, size: int) -> sp.csr_matrix:
    """Sum point blocks ``(P, m, C, m, C)`` (rows ``(l, c)``, columns ``(k, d)``) into the
    interleaved ``(C size)²`` matrix, row ``C l + c``."""
    P, m = cols.shape
    index = (C * cols[:, :, None] + np.arange(C)).reshape(P, m * C)
    rows = np.broadcast_to(index[:, :, None], (P, m * C, m * C))
    return sp.coo_matrix((blocks.reshape(P, m * C, m * C).ravel(),
                          (rows.ravel(), np.swapaxes(rows, 1, 2).ravel())),
                         shape=(C * size,) * 2).tocsr()


def energy_matrix(surface: Any, form: Form, points: Array, weights: Array) -> sp.csr_matrix:
    """``K = Σ_q ω_q e_qᵀ C_q e_q`` over the quadrature ``(points, weights)``, ``(C N)²``
    interleaved: ``C = Q Λ Qᵀ`` per point, so ``K = Zᵀ Ω Z`` with the rows
    ``Z = Λ^½ Qᵀ e`` of all points stacked (one sparse product; cut-cell weights may be
    negative, so ``Ω`` stays apart)."""
    geo, _ = surface_geometry(surface, points)
    V, Cm = form.strains(geo)
    lam, Q = np.linalg.eigh(Cm)
    W = np.sqrt(np.clip(lam, 0.0, None))[:, :, None] * np.swapaxes(Q, 1, 2)
    local = local_values(surface, points, list(SLOTS))
    vals = np.stack([local.values[s] for s in SLOTS])                   # (5, P, m)
    U = np.einsum("qji,qics->qjcs", W, V)
    data = np.einsum("qjcs,sqk->qjck", U, vals)                         # (P, R, C, m)
    P, R, C, m = data.shape
    rows = np.broadcast_to((np.arange(P)[:, None] * R + np.arange(R))[:, :, None, None],
                           data.shape)
    cols = np.broadcast_to(C * local.cols[:, None, None, :] + np.arange(C)[None, None, :, None],
                           data.shape)
    size = surface.control_points.shape[0] * surface.control_points.shape[1]
    Z = sp.csr_matrix((data.ravel(), (rows.ravel(), cols.ravel())), shape=(P * R, C * size))
    K = Z.T @ sp.diags(np.repeat(weights, R)) @ Z
    return ((K + K.T) * 0.5).tocsr()


def scalar_mass(surface: Any, points: Array, weights: Array, density: float) -> sp.csr_matrix:
    """``M = ρ ∫_Ω b_k b_l √g du dv`` of one coordinate."""
    geo, _ = surface_geometry(surface, points)
    B = surface_values(surface, points, [(0, 0)])[(0, 0)]
    return (B.T @ sp.diags(density * weights * geo.sqrt_g) @ B).tocsr()


def coefficients(form: Form, geo: Geometry) -> Array:
    """``A_ts`` at every point, ``(P, 5, 5, C, C)``."""
    V, Cm = form.strains(geo)
    return np.einsum("qict,qij,qjds->qtscd", V, Cm, V)


def coefficient_derivatives(form: Form, geo: Geometry, x: dict, h: Array
                            ) -> tuple[Array, Array]:
    """``∂_u A``, ``∂_v A`` (module docstring): ``A`` on the lines ``a_α ± τ x_,αγ``,
    ``a_αβ ± τ x_,αβγ``, central differences at ``τ = h`` and ``2h`` combined as
    ``(4 D_h − D_2h)/3``."""
    third = {(1, 0): (x[2, 0], x[1, 1], x[3, 0], x[2, 1], x[1, 2]),
             (0, 1): (x[1, 1], x[0, 2], x[2, 1], x[1, 2], x[0, 3])}
    out = []
    for gamma in ((1, 0), (0, 1)):
        da1, da2, d11, d12, d22 = third[gamma]
        da, dda = np.stack([da1, da2], 1), np.stack([d11, d12, d22], 1)

        def at(tau: Array) -> Array:
            t = tau[:, None, None]
            return coefficients(form, geometry(geo.a + t * da, geo.a2 + t * dda))

        diff = [(at(k * h) - at(-k * h)) / (2 * k * h)[:, None, None, None, None]
                for k in (1.0, 2.0)]
        out.append((4 * diff[0] - diff[1]) / 3)
    return out[0], out[1]


def penalty_scales(A: Array) -> tuple[Array, Array, Array]:
    """``Γ_t = ½(A_{u,u} + A_{v,v})``, ``Γ_b = ⅓(A_{uu,uu} + ½ A_{uv,uv} + A_{vv,vv})``
    (``(P, C, C)``, the membrane and bending stiffness each component meets) and the scalar
    ``w_b``, the largest diagonal entry of the second-order block (``A_{uv,uv}`` halved)."""
    diag = np.diagonal(np.diagonal(A, axis1=1, axis2=2), axis1=1, axis2=2)   # (P, 5, C)
    w_b = np.maximum(np.maximum(diag[:, 2], diag[:, 4]), diag[:, 3] / 2).max(axis=1)
    return (0.5 * (A[:, 0, 0] + A[:, 1, 1]),
            (A[:, 2, 2] + 0.5 * A[:, 3, 3] + A[:, 4, 4]) / 3, w_b)


def nitsche_matrix(surface: Any, form: Form, p: Array, ds: Array, n: Array, s: Array,
                   clamped: NDArray[np.bool_], h: Array, beta: float,
                   displacement_held: bool = False) -> sp.csr_matrix:
    """Nitsche's terms (module docstring) at the held loop points ``p (P, 2)`` with weights
    ``ds``, outward normals ``n``, tangents ``s``; ``clamped`` per point (else pinned),
    ``h`` the knot cell at each point.

    With ``displacement_held`` the loop's ``d = 0`` is held exactly by a constraint map
    ``T``: every term with the value ``v_0`` (of the test or trial function) as a factor,
    ``−∮ g_0(d)·v_0 + g_0(v)·d_0`` and ``γ_0 ∮ d·v``, vanishes in ``Tᵀ K T`` and is left
    out, with the third derivatives and ``∂_γ A`` that ``g_0`` needs; what remains is
    ``−∮ g_u(d) v_u + g_v(d) v_v + (d ↔ v) + γ_1 ∮ Σ_m ρ_m(d) ρ_m(v)`` (clamped) or
    ``−∮ (g·s)(∂_s v) + (d ↔ v)`` (pinned).
    """
    C = form.components
    size = surface.control_points.shape[0] * surface.control_points.shape[1]
    if not len(p):
        return sp.csr_matrix((C * size,) * 2)
    full = not displacement_held
    geo, x = surface_geometry(surface, p, third=full)
    A = coefficients(form, geo)
    orders = [(0, 0)] + list(SLOTS) + ([(3, 0), (2, 1), (1, 2), (0, 3)] if full else [])
    local = local_values(surface, p, orders)
    vals = np.stack([local.values[o] for o in SLOTS])                           # (5, P, m)
    nu, nv = (n[:, k][:, None, None, None] for k in (0, 1))
    w = ds[:, None, None, None]
    gu = (_sigma(A, 2, vals) * nu + 0.5 * _sigma(A, 3, vals) * nv) * w        # ds g_u, ds g_v
    gv = (_sigma(A, 4, vals) * nv + 0.5 * _sigma(A, 3, vals) * nu) * w
    su, sv = (s[:, k][:, None, None, None] for k in (0, 1))
    gs = gu * su + gv * sv               # pinned: (g·s)(∂_s v) = v_u s_u (g·s) + v_v s_v (g·s)
    cl = clamped[:, None, None, None]
    vu, vv = local.values[1, 0], local.values[0, 1]
    b = _outer(vu, np.where(cl, gu, su * gs)) + _outer(vv, np.where(cl, gv, sv * gs))
    _, _, w_b = penalty_scales(A)
    gamma1 = beta * w_b / h * ds * clamped
    rho = form.rotation(geo, n)                                          # (P, M, C, 2)
    r = (np.einsum("qmc,qk->qmkc", rho[..., 0], vu) + np.einsum("qmc,qk->qmkc", rho[..., 1], vv))
    pen = np.einsum("qmlc,qmkd->qlckd", gamma1[:, None, None, None] * r, r)
    if full:
        b0, pen0 = _value_terms(form, geo, x, A, local, n, ds, h, beta)
        b, pen = b + b0, pen + pen0
    blocks = pen - b - np.transpose(b, (0, 3, 4, 1, 2))
    return _scatter(local.cols, blocks, C, size)


def _sigma(coef: Array, t: int, basis: Array) -> Array:
    """The rows of ``σ_t = Σ_s coef_ts D^s`` on ``basis (5, P, m)``, ``(P, C, m, C)``."""
    return np.einsum("qscd,sqk->qckd", coef[:, t], basis)


def _outer(test: Array, g: Array) -> Array:
    """``test (P, m) ⊗ g (P, C, m, C)`` as point blocks ``(P, m, C, m, C)``."""
    return np.einsum("ql,qckd->qlckd", test, g)


def _value_terms(form: Form, geo: Geometry, x: dict, A: Array, local: Local, n: Array,
                 ds: Array, h: Array, beta: float) -> tuple[Array, Array]:
    """The terms of the value ``v_0`` (:func:`nitsche_matrix`): the blocks of
    ``ds g_0(d)·v_0`` and the penalty ``γ_0 ds v_0 v_0``, ``γ_0 = β (Γ_b/h³ + Γ_t/h)``."""
    dAu, dAv = coefficient_derivatives(form, geo, x, STEP * h)
    vals = np.stack([local.values[o] for o in SLOTS])
    shifted = [np.stack([local.values[a + da, b + db] for a, b in SLOTS])
               for da, db in ((1, 0), (0, 1))]

    def d_sigma(t: int, axis: int) -> Array:
        return _sigma((dAu, dAv)[axis], t, vals) + _sigma(A, t, shifted[axis])

    nu, nv = (n[:, k][:, None, None, None] for k in (0, 1))
    g0 = (_sigma(A, 0, vals) * nu + _sigma(A, 1, vals) * nv
          - (d_sigma(2, 0) * nu + 0.5 * (d_sigma(3, 0) * nv + d_sigma(3, 1) * nu)
             + d_sigma(4, 1) * nv))
    v0 = local.values[0, 0]
    tension, bending, _ = penalty_scales(A)
    gamma0 = beta * (bending / h[:, None, None] ** 3 + tension / h[:, None, None])
    return (_outer(v0, g0 * ds[:, None, None, None]),
            np.einsum("q,ql,qk,qcd->qlckd", ds, v0, v0, gamma0))
