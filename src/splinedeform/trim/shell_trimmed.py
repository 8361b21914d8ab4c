"""The Kirchhoff–Love shell (:mod:`splinedeform.physics.shell`) on a trimmed region.

The shell's strains ``ε_αβ``, ``κ_αβ`` (Kiendl's,
:func:`~splinedeform.physics.shell.strain_vectors`) and constitutive matrix ``H`` are the
strain rows of an :mod:`.energy_forms` energy with three components, ``C = √g diag(E t/(1−ν²) H, E t³/(12(1−ν²)) H)``; membrane and bending
stiffness, the mass ``ρ t ∫_Ω N_k N_l dA ⊗ I₃`` and the loads (:mod:`splinedeform.loads`)
are integrated over the trimmed cells with the parametric plate's trimmed quadrature.
The unknowns are the interleaved displacements of the inner B-splines, ``T = E ⊗ I₃``
with Höllig's extension ``E``: each component is a scalar spline field, and the extension
reproduces polynomials component by component, so the displacement stays a B-spline
surface and every output works on it.

**NURBS weights.** The shape functions are the surface's basis: polynomial, rational with
product weights ``w_kl = a_k b_l`` or with general weights
(:attr:`~splinedeform.Surface.net_weights`), ``R_kl = w_kl b_k b_l / W``, whose derivatives
up to the third order (Nitsche's terms) come from the quotient rule at every trimmed point
(:func:`~.values.surface_values`, :func:`splinedeform.rational.basis_derivatives`); the
geometry ``x = Σ R_kl p_kl`` and its derivatives from the same rows, so the strains are
the untrimmed shell's (:mod:`splinedeform.physics.shell`). A rational field is extended
through its numerator's coefficients (``E = diag(1/w) E_b diag(w_I)``,
:func:`~.web.web_basis`): the fields ``P / W`` with ``P`` a polynomial of the B-splines'
degree are reproduced, the rigid motions among them where ``W`` and ``W x`` are such
polynomials (a rational Bézier patch, refined or not).

**Held loops by Nitsche's method, not by Höllig's weight function.** A weight ``w``
vanishing on the loop makes the displacement ``w Σ c_k b_k``, no longer in the surface's
own spline space (no control net, mesh or CAD export could hold it), and a weight that is
smooth exists only for special loops (``trim/weight.py``: circles, convex polygons with
corners of infinite curvature), while CAD loops are arbitrary chains of trims. Nitsche's
terms need only the loop's points, and they are consistent for the shell's three
components: integrating the energy by parts in ``(u, v)`` (:mod:`.energy_forms`) gives the
boundary form ``∮ g_0·v + g_u·v_u + g_v·v_v``, where ``g_β`` comes from the second
derivatives alone, which enter the strains only through ``κ_αβ ∋ d_,αβ·a_3``, so
``g_β ∥ a_3``. A clamped loop holds ``d = 0`` (hence ``∂_s d = 0``) and the rotation
``a_3·∂_n d = 0``: the exact solution makes ``b(v, d) = ∮ g_0(v)·d + (g(v)·n) a_3·∂_n d
= 0`` although its in-plane ``∂_n d`` (the membrane strain at the loop) is not zero, so
the penalty holds ``d`` and ``a_3·∂_n d`` only. A pinned loop holds ``d`` (``b_p`` without
the moment ``g·n``, which is natural). The penalties scale with the membrane and bending
coefficients at each point (:func:`~.energy_forms.penalty_scales`).

The rectangle's edges ``u0 … v1`` of a holed rectangle (the outer loop is the parameter
rectangle) take ``free``, ``pinned`` or ``clamped`` through the same Nitsche terms on the
points of that loop (:func:`edge_nitsche`; the shell's other edge kinds of
:mod:`splinedeform.physics.shell_edges` are not combined with the extension yet).

**Fixed control points.** A mask of fixed points (``(n_u, n_v)``, or per component with
the three components of each point alike) is taken as the plate's
(:func:`~.holed.with_edges`): ``T = E_F ⊗ I₃`` with the extension ``E_F`` over the free
inner B-splines, a held inner or outer B-spline's coefficient at rest, a held dead one
(support outside the region) at rest already. Held components of a point but not all
are refused: the three components follow one extension map.
"""

from __future__ import annotations

from dataclasses import dataclass
from types import SimpleNamespace
from typing import Any, Mapping

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray

from ..errors import InputError
from ..physics.shell import ShellMaterial, constitutive, strain_vectors
from ..physics.shell_rigid import RigidMotions, free_rigid_motions
from .energy_forms import Array, Form, Geometry, nitsche_matrix
from .holed import with_edges
from .model_matrices import (_cell_size, form_matrices, held_live, loop_conditions,
                             loop_quadrature, nitsche_penalty, quadrature_of)
from .surface_trim import (extension_knots, holed_rectangle, net_weights_of, surface_degrees,
                           trim_grid)
from .web import web_basis

#: a point of the rectangle's loop within this fraction of its longer side from a side
#: lies on it
SIDE = 1e-9


def shell_form(material: ShellMaterial) -> Form:
    """The shell's :class:`~.energy_forms.Form` (module docstring)."""
    E, nu, t = material.E, material.nu, material.thickness
    membrane, bending = E * t / (1 - nu ** 2), E * t ** 3 / (12 * (1 - nu ** 2))

    def strains(geo: Geometry) -> tuple[Array, Array]:
        grid = SimpleNamespace(a=np.swapaxes(geo.a, 0, 1)[:, :, None],
                               a2=np.swapaxes(geo.a2, 0, 1)[:, :, None],
                               sqrt_g=geo.sqrt_g[:, None])
        V = strain_vectors(grid, slice(None))[:, 0]                      # (P, 6, 3, 5)
        H = constitutive(geo.g_inv, nu) * geo.sqrt_g[:, None, None]
        C = np.zeros((len(H), 6, 6))
        C[:, :3, :3], C[:, 3:, 3:] = membrane * H, bending * H
        return V, C

    def rotation(geo: Geometry, n: Array) -> Array:
        return geo.a3[:, None, :, None] * n[:, None, None, :]           # a_3·∂_n d

    return Form(3, strains, rotation, material.density * t)


@dataclass(frozen=True)
class TrimmedShell:
    """``K``, ``M`` over the interleaved ``3N`` displacements, ``T = E ⊗ I₃``, the presets
    of edges and loops, and the free rigid motions (:func:`rigid_motions`)."""

    stiffness: sp.csr_matrix
    mass: sp.csr_matrix
    T: sp.csr_matrix
    edges: dict[str, str]
    motions: RigidMotions


def rigid_motions(T: sp.csr_matrix, points: Array, holds: bool,
                  at_rest: NDArray[np.bool_] | None = None) -> RigidMotions:
    """The free rigid motions: none where a held loop's penalty takes them, else those in
    ``range T`` on the control points the region moves (``T``'s nonzero rows; the others
    stay at rest) and on the fixed points ``at_rest`` (flat, live ones: zero rows of ``T``
    that are points of the shell, :func:`~.model_matrices.held_live`)."""
    if holds:
        return RigidMotions(np.zeros((T.shape[1], 0)), np.zeros((6, 0)))
    moving = np.diff(T.indptr)[::3] > 0
    moving = np.flatnonzero(moving if at_rest is None else moving | at_rest)
    rows = (3 * moving[:, None] + np.arange(3)).ravel()
    return free_rigid_motions(T[rows], points.reshape(-1, 3)[moving])


def trimmed_shell(surface: Any, material: ShellMaterial,
                  boundary: str | Mapping[str, str] | None, fixed: Any = None) -> TrimmedShell:
    """The shell of a trimmed surface (module docstring); ``boundary`` names its loops
    (``{"outer": "clamped", "hole1": "free"}``, or one preset for every loop); ``fixed``
    a mask of fixed control points (:func:`point_mask`, module docstring)."""
    degrees = surface_degrees(surface)
    if min(degrees) < 2:
        raise InputError("the Kirchhoff–Love shell needs degree >= 2 in u and v (curvatures)")
    mask = None if fixed is None else point_mask(surface, fixed)
    edges, loops, held = loop_conditions(surface, "free" if boundary is None else boundary)
    rectangle = holed_rectangle(surface)
    kept = {e: k for e, k in edges.items() if k != "free"}
    if (held or kept) and min(degrees) < 3:
        raise InputError("a pinned or clamped trim loop of the shell needs degree >= 3 (third "
                         f"derivatives in Nitsche's terms), got {degrees}")
    form = shell_form(material)
    K, mass = form_matrices(surface, form, held)
    if kept:
        K = K + edge_nitsche(surface, form, edges)
    M = sp.kron(mass, sp.identity(3))
    classes = quadrature_of(surface).classes
    if mask is not None:                  # the edges held by Nitsche's terms, not here
        try:
            E, _ = with_edges(surface, {e: "free" for e in edges}, classes, mask)
        except InputError as exc:         # marked: the mask is the cause (a body names its face)
            exc.fixed_points = True  # type: ignore[attr-defined]
            raise
    elif rectangle:
        E, _ = with_edges(surface, {e: "free" for e in edges}, classes, None)
    else:
        E = web_basis(classes, degrees, knots=extension_knots(surface),
                      weights=net_weights_of(surface)).extension
    T = sp.kron(sp.csr_matrix(E), sp.identity(3), format="csr")
    at_rest = None if mask is None else held_live(surface, classes, mask).ravel()
    return TrimmedShell(((K + K.T) * 0.5).tocsr(), M.tocsr(), T, {**edges, **loops},
                        rigid_motions(T, surface.control_points, bool(held or kept), at_rest))


def point_mask(surface: Any, fixed: Any) -> NDArray[np.bool_]:
    """A trimmed shell's mask of fixed control points ``(n_u, n_v)``: given so, or per
    component ``(n_u, n_v, 3)`` holding the three components of each point alike (the
    three follow one extension map, ``T = E ⊗ I₃``)."""
    mask = np.asarray(fixed)
    net = tuple(surface.shape)
    if mask.shape not in (net, net + (3,)) or mask.dtype != bool:
        raise InputError(f"a trimmed shell's fixed mask is boolean, of shape (n_u, n_v) = "
                         f"{net} or {net + (3,)}, got {mask.shape} of dtype {mask.dtype}")
    if mask.ndim == 3:
        mixed = np.argwhere(mask.any(axis=-1) & ~mask.all(axis=-1))
        if len(mixed):
            listed = ", ".join(str(list(map(int, ij))) for ij in mixed[:4])
            raise InputError("a trimmed shell's three displacement components follow one "
                             "extension map: its mask holds a control point whole or not at "
                             f"all; point(s) {listed} hold some components only")
        mask = mask.all(axis=-1)
    return mask


def edge_nitsche(surface: Any, form: Form, edges: Mapping[str, str]) -> sp.csr_matrix:
    """Nitsche's terms of the held edges ``u0 … v1`` of a holed rectangle: the points of
    its outer loop (the rectangle, :func:`~.model_matrices.loop_quadrature`), each with
    the preset of the side it lies on."""
    grid = trim_grid(surface)
    p, ds, n, s, _, _ = loop_quadrature(surface.trim, grid, max(surface_degrees(surface)) + 2,
                                        surface.trim.loops[:1])
    (_, lu), (_, lv) = surface.domain
    p = np.clip(p, 0.0, [lu, lv])
    tol = SIDE * max(lu, lv)
    preset = np.full(len(p), "free", dtype=object)
    for name, on_side in (("u0", p[:, 0] < tol), ("u1", p[:, 0] > lu - tol),
                          ("v0", p[:, 1] < tol), ("v1", p[:, 1] > lv - tol)):   # the sides
        preset[on_side] = edges[name]
    on = preset != "free"
    return nitsche_matrix(surface, form, p[on], ds[on], n[on], s[on], preset[on] == "clamped",
                          _cell_size(grid, p[on]), nitsche_penalty(max(surface_degrees(surface))))
