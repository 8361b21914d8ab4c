"""Linear Kirchhoff–Love shell, isogeometric and rotation-free (Kiendl et al. 2009).

Unknowns are the displacements ``d`` of the control points, x, y and z coupled (``3n``,
interleaved: dof ``3k + c``). With the covariant basis ``a_α``, ``a_αβ`` and unit normal
``a_3`` of the initial surface, the linearised strains are::

    ε_αβ = ½ (a_α·d_,β + a_β·d_,α)
    κ_αβ = d_,αβ·a_3 + (1/√g) [d_,1·(a_2 × ã_αβ) + d_,2·(ã_αβ × a_1)],
           ã_αβ = a_αβ − (a_αβ·a_3) a_3

(the second term is ``a_αβ·δa_3`` with ``δa_3 = (I − a_3 a_3ᵀ)(d_,1 × a_2 + a_1 × d_,2)/√g``).
Energy ``½ ∫ (E t/(1−ν²)) εᵀ H ε + (E t³/(12(1−ν²))) κᵀ H κ dA`` in Voigt form
``(·_11, ·_22, 2·_12)`` with the contravariant constitutive matrix of Kiendl (2009)::

    H = [[g¹¹²,  ν g¹¹g²² + (1−ν) g¹²²,  g¹¹g¹²],
         [·,     g²²²,                   g²²g¹²],
         [·,     ·,    ½((1−ν) g¹¹g²² + (1+ν) g¹²²)]]

and mass ``ρ t ∫ |d|² dA``.

The shape functions are the surface's basis: the tensor products ``N_k(u) N_l(v)`` of its
1-D bases (polynomial or rational with product weights ``w_kl = a_k b_l``), or, with
general weights (:attr:`~splinedeform.Surface.net_weights`), the rational
``R_kl = w_kl N_k N_l / W``, whose derivatives up to second order come from the quotient
rule at every Gauss point (:func:`splinedeform.rational.basis_derivatives`, computed with
the metric's grid, :func:`.metric.grid`). The quadrature is the same ``p + 2`` points per
cell and direction for both: the integrand is rational already for polynomial bases (the
inverse metric), and the rule is held to the discretisation error by the convergence tests
(``tests/test_shell_weights.py``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray

from ..errors import InputError
from ..surface import Surface
from . import metric
from .shell_assembly import Pattern, assemble_cells

Array = NDArray[np.float64]
#: derivative orders ``(p, r)`` of the five shape derivatives ``s`` of :func:`cell_shapes`
SLOTS = ((1, 0), (0, 1), (2, 0), (1, 1), (0, 2))


@dataclass(frozen=True)
class ShellMaterial:
    """Young's modulus ``E > 0``, Poisson ratio ``0 <= ν < 0.5``, thickness ``t > 0``, density ``ρ > 0``.

    Damping (both ``>= 0``): ``damping`` ``γ`` is a viscous force per unit surface area and
    unit velocity, ``rayleigh`` ``β`` is stiffness proportional, ``C = (γ/(ρt)) M + β K``,
    so mode ``i`` has ``c_i = γ/(ρt) + β ω_i²`` (critically damped at ``c_i = 2 ω_i``).
    """

    E: float
    nu: float
    thickness: float
    density: float = 1.0
    damping: float = 0.0
    rayleigh: float = 0.0

    def __post_init__(self) -> None:
        for name in ("E", "nu", "thickness", "density", "damping", "rayleigh"):
            value = getattr(self, name)
            try:
                value = float(value)
            except (TypeError, ValueError):
                raise InputError(f"shell material {name} must be a number, got {value!r}") from None
            if not np.isfinite(value):
                raise InputError(f"shell material {name} must be finite, got {value!r}")
            object.__setattr__(self, name, value)
        if self.E <= 0 or self.thickness <= 0 or self.density <= 0:
            raise InputError("shell material needs E > 0, thickness > 0 and density > 0, got "
                             f"E={self.E:g}, thickness={self.thickness:g}, "
                             f"density={self.density:g}")
        if not 0 <= self.nu < 0.5:
            raise InputError(f"shell material Poisson ratio nu must be in [0, 0.5), got {self.nu:g}")
        if self.damping < 0 or self.rayleigh < 0:
            raise InputError("shell material damping and rayleigh must be >= 0, got "
                             f"damping={self.damping:g}, rayleigh={self.rayleigh:g}")


def constitutive(g_inv: Array, nu: float) -> Array:
    """Kiendl's ``H`` in Voigt form at every point, ``(..., 3, 3)``."""
    g11, g12, g22 = g_inv[..., 0, 0], g_inv[..., 0, 1], g_inv[..., 1, 1]
    H = np.empty(g11.shape + (3, 3))
    H[..., 0, 0] = g11 ** 2
    H[..., 1, 1] = g22 ** 2
    H[..., 0, 1] = H[..., 1, 0] = nu * g11 * g22 + (1 - nu) * g12 ** 2
    H[..., 0, 2] = H[..., 2, 0] = g11 * g12
    H[..., 1, 2] = H[..., 2, 1] = g22 * g12
    H[..., 2, 2] = 0.5 * ((1 - nu) * g11 * g22 + (1 + nu) * g12 ** 2)
    return H


def strain_operators(G: metric.Grid, N: dict[tuple[int, int], Array]) -> tuple[Array, Array]:
    """Membrane and bending operators ``B_m, B_b`` of shape ``(Qu, Qv, 3, k, 3)``.

    ``ε_i = Σ_kc B_m[i, k, c] d_kc`` (Voigt ``i``), likewise ``κ``.
    """
    a1, a2 = G.a[0], G.a[1]
    a3 = np.cross(a1, a2) / G.sqrt_g[..., None]
    N1, N2 = N[1, 0], N[0, 1]
    Bm = np.stack([N1[..., :, None] * a1[..., None, :],
                   N2[..., :, None] * a2[..., None, :],
                   N2[..., :, None] * a1[..., None, :] + N1[..., :, None] * a2[..., None, :]],
                  axis=2)
    rows = []
    for c, (second, factor) in enumerate(((N[2, 0], 1.0), (N[0, 2], 1.0), (N[1, 1], 2.0))):
        a_ab = G.a2[(0, 2, 1)[c]]
        tilde = a_ab - np.sum(a_ab * a3, -1)[..., None] * a3
        w1 = np.cross(a2, tilde) / G.sqrt_g[..., None]
        w2 = np.cross(tilde, a1) / G.sqrt_g[..., None]
        rows.append(factor * (second[..., :, None] * a3[..., None, :]
                              + N1[..., :, None] * w1[..., None, :]
                              + N2[..., :, None] * w2[..., None, :]))
    return Bm, np.stack(rows, axis=2)


def matrices(surface: Surface, material: ShellMaterial) -> tuple[sp.csr_matrix, sp.csr_matrix]:
    """Stiffness ``K`` and consistent mass ``M`` over the ``3n`` interleaved displacements.

    ``K = Σ_cells Σ_q Bᵀ D B`` with ``B = [B_m; B_b]`` (6 rows) and
    ``D = √g w_q diag(E t/(1−ν²) H, E t³/(12(1−ν²)) H)``, ``M = ρ t ∫ N_k N_l dA ⊗ I₃``;
    cell by cell into a precomputed pattern (:mod:`.shell_assembly`); ``N_k`` is the
    surface's basis (the module docstring), general weights included. Across a ``C^0``
    knot line the cells hold nothing: :class:`~.shell_formulation.ShellFormulation` ties
    the slopes exactly where the rest shape is smooth across it
    (:mod:`.coupling_ties`) and adds its rotation penalty elsewhere (:mod:`.coupling_model`).
    """
    if min(surface.basis_u.degree, surface.basis_v.degree) < 2:
        raise InputError("the Kirchhoff–Love shell needs degree >= 2 in u and v (curvatures)")
    G = metric.grid(surface, extra_points=1)
    q = (surface.basis_u.degree + 2, surface.basis_v.degree + 2)    # Gauss points per cell
    n_u, n_v = surface.basis_u.size, surface.basis_v.size
    cells_u, cells_v = G.index_u[::q[0]], G.index_v[::q[1]]
    E, nu, t = material.E, material.nu, material.thickness
    dA = G.weight * G.sqrt_g
    membrane, bending = E * t / (1 - nu ** 2), E * t ** 3 / (12 * (1 - nu ** 2))

    def stiffness(rows: slice) -> Array:
        points = slice(rows.start * q[0], rows.stop * q[0])
        S = cell_shapes(G, points, q)                               # (A, B, qu qv, 5, k)
        V = by_cell(strain_vectors(G, points), q)                   # (A, B, qu qv, 6, 3, 5)
        H = by_cell(constitutive(G.g_inv[points], nu), q)
        w = by_cell(dA[points], q)[..., None, None]
        # D = L Lᵀ per point, so Bᵀ D B = (Lᵀ B)ᵀ (Lᵀ B) with Lᵀ B = (Lᵀ V) S
        L = np.linalg.cholesky(H)
        Lt = np.concatenate([np.swapaxes(L, -1, -2) * np.sqrt(membrane * w),
                             np.swapaxes(L, -1, -2) * np.sqrt(bending * w)], axis=-2)
        # (Lᵀ V)[i, c, s] = Σ_j Lᵀ[i, j] V[j, c, s], membrane and bending rows apart
        LV = np.concatenate([np.einsum("...ij,...jcs->...ics", Lt[..., :3, :], V[..., :3, :, :]),
                             np.einsum("...ij,...jcs->...ics", Lt[..., 3:, :], V[..., 3:, :, :])],
                            axis=-3)
        C = LV.reshape(LV.shape[:3] + (18, 5)) @ S                  # (A, B, qu qv, 18, k)
        C = C.reshape(C.shape[:2] + (-1, 3 * C.shape[-1]))          # rows (q, i), cols (c, k)
        return np.swapaxes(C, -1, -2) @ C

    K = assemble_cells(Pattern.of(cells_u, cells_v, n_u, n_v, 3), cells_u, cells_v, stiffness)

    def mass(rows: slice) -> Array:
        points = slice(rows.start * q[0], rows.stop * q[0])
        if G.shapes is not None:                                    # R_kl, general weights
            N0 = by_cell(G.shapes[0, 0][points], q)                 # (A, B, qu qv, k)
        else:
            N0 = (G.values_u[0][points, None, :, None] * G.values_v[0][None, :, None, :])
            N0 = by_cell(N0.reshape(N0.shape[:2] + (-1,)), q)
        w = by_cell(material.density * t * dA[points], q)[..., None]
        return np.swapaxes(N0, -1, -2) @ (w * N0)

    scalar = assemble_cells(Pattern.of(cells_u, cells_v, n_u, n_v, 1), cells_u, cells_v, mass)
    # mass ρt ∫ N_k N_l dA for each coordinate alike: the scalar matrix ⊗ I₃ (interleaved)
    return K, sp.kron(scalar, sp.identity(3), format="csr")


def cell_shapes(G: metric.Grid, points: slice, q: tuple[int, int]) -> Array:
    """``N_,1, N_,2, N_,11, N_,12, N_,22`` at the grid rows ``points`` by cells,
    ``(A, B, q_u q_v, 5, k)``, the layout of :func:`by_cell` without its copy:
    ``N_{,u^p v^r}[(x, y), (k_u, k_v)] = B_u^(p)[x, k_u] B_v^(r)[y, k_v]``; with general
    weights the rational ``D^(p,r) R_k`` of the grid (:attr:`.metric.Grid.shapes`), by cells
    (a copy)."""
    if G.shapes is not None:
        R = np.stack([G.shapes[order][points] for order in SLOTS], axis=2)   # (Qa, Qv, 5, k)
        return by_cell(R, q)
    (qu, qv), (_, Qa, pu), (_, Qv, pv) = q, G.values_u[:, points].shape, G.values_v.shape
    Bu = G.values_u[:, points].reshape(3, Qa // qu, 1, qu, 1, pu, 1)
    Bv = G.values_v.reshape(3, 1, Qv // qv, 1, qv, 1, pv)
    S = np.stack([Bu[p] * Bv[r] for p, r in SLOTS], axis=4)      # (A, B, qu, qv, 5, pu, pv)
    return S.reshape(S.shape[:2] + (qu * qv, 5, pu * pv))


def strain_vectors(G: metric.Grid, points: slice) -> Array:
    """``V (Qa, Qv, 6, 3, 5)``: ``B[i, c, k] = Σ_s V[i, c, s] S[s, k]`` (:func:`point_shapes`).

    Rows ``ε_11, ε_22, 2ε_12`` then ``κ_11, κ_22, 2κ_12`` of :func:`strain_operators`,
    each a combination of the five shape derivatives ``s`` with vector coefficients.
    """
    a1, a2 = G.a[0, points], G.a[1, points]
    sqrt_g = G.sqrt_g[points][..., None]
    a3 = np.cross(a1, a2) / sqrt_g
    V = np.zeros(a1.shape[:2] + (6, 3, 5))
    V[..., 0, :, 0] = a1
    V[..., 1, :, 1] = a2
    V[..., 2, :, 1] = a1
    V[..., 2, :, 0] = a2
    for row, (second, slot, factor) in enumerate(((0, 2, 1.0), (2, 4, 1.0), (1, 3, 2.0))):
        a_ab = G.a2[second, points]
        tilde = a_ab - np.sum(a_ab * a3, -1)[..., None] * a3
        V[..., 3 + row, :, slot] = factor * a3
        V[..., 3 + row, :, 0] = factor * np.cross(a2, tilde) / sqrt_g
        V[..., 3 + row, :, 1] = factor * np.cross(tilde, a1) / sqrt_g
    return V


def by_cell(A: Array, q: tuple[int, int]) -> Array:
    """Grid array ``(Q_a, Q_v, ...)`` → ``(cells_a, cells_v, q_u q_v, ...)`` by cells.

    The ``q_u × q_v`` Gauss points of each cell are consecutive in the grid
    (:func:`~splinedeform.quadrature.gauss_points`).
    """
    (Qa, Qv), (qu, qv) = A.shape[:2], q
    A = A.reshape((Qa // qu, qu, Qv // qv, qv) + A.shape[2:]).swapaxes(1, 2)
    return A.reshape(A.shape[:2] + (qu * qv,) + A.shape[4:])
