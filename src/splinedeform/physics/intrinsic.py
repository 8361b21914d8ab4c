"""The thin plate under tension measured on the surface (``physics = "intrinsic"``).

For each displacement coordinate ``d`` (x, y and z alike, so one ``n × n`` eigenproblem
still serves all three)::

    E(d) = ½ ∫ T |∇_S d|² dA + ½ ∫ D (Δ_S d)² dA,     kinetic ½ ∫ μ ḋ² dA

with the first fundamental form of the initial surface: ``|∇_S d|² = g^αβ d_,α d_,β``,
``Δ_S d = g^αβ (d_,αβ − Γ^γ_αβ d_,γ)`` (Laplace–Beltrami) and ``dA = √g du dv``. The
Galerkin matrices are assembled on a tensor Gauss grid (:mod:`.metric`)::

    K_kl = Σ_q w_q √g_q [T g^αβ N_k,α N_l,β + D (Δ_S N_k)(Δ_S N_l)],
    M_kl = Σ_q w_q √g_q μ N_k N_l,

cell by cell: with ``g^αβ = C Cᵀ`` per point, each cell's block is ``BᵀB`` for the rows
``B = [√(T w √g) Cᵀ ∇N; √(D w √g) Δ_S N]`` of all its points stacked, one batched
product, scattered into a precomputed sparse pattern (:mod:`.shell_assembly`).

The result depends on the surface, not on its parametrisation, up to discretisation error.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray

from ..errors import InputError
from ..material import Material
from ..surface import Surface
from . import metric
from .shell import by_cell
from .shell_assembly import Pattern, assemble_cells

Array = NDArray[np.float64]


def coefficients(material: Material) -> tuple[float, float]:
    """Tension ``T = w10 = w01`` and flexural rigidity ``D = w20 = w02`` (``w11`` 0 or ``D``).

    The surface has no preferred direction, so the weights must be isotropic. ``(Δ_S d)²``
    differs from the paper's ``d_uu² + 2 d_uv² + d_vv²`` (on a plane) by a null Lagrangian
    that vanishes on clamped edges, so ``w11 = D`` names the same plate; ``w11 = 0`` is
    accepted as the common way of writing it.
    """
    m = material
    if m.w10 != m.w01 or m.w20 != m.w02 or m.w11 not in (0.0, m.w20):
        raise InputError(
            "physics 'intrinsic' is isotropic: it needs w10 == w01 (tension T) and "
            "w20 == w02 (flexural rigidity D) with w11 equal to 0 or D, got "
            f"w10={m.w10:g}, w01={m.w01:g}, w20={m.w20:g}, w11={m.w11:g}, w02={m.w02:g}")
    return m.w10, m.w20


def laplace_beltrami(G: metric.Grid, N: dict[tuple[int, int], Array]) -> Array:
    """``Δ_S N_k = g^αβ (N_k,αβ − Γ^γ_αβ N_k,γ)`` at every grid point, ``(Qu, Qv, pu·pv)``."""
    gi = G.g_inv
    weights = (gi[..., 0, 0], 2 * gi[..., 0, 1], gi[..., 1, 1])          # 11, 12, 22
    second = (N[2, 0], N[1, 1], N[0, 2])
    first = (N[1, 0], N[0, 1])
    out = np.zeros_like(N[0, 0])
    for c, (w, d2) in enumerate(zip(weights, second)):
        correction = G.gamma[0, c][..., None] * first[0] + G.gamma[1, c][..., None] * first[1]
        out += w[..., None] * (d2 - correction)
    return out


def matrices(surface: Surface, material: Material, lumped: bool = False
             ) -> tuple[sp.csr_matrix, sp.csr_matrix]:
    """Stiffness ``K`` and mass ``M`` (full, ``n_u n_v`` square) of the intrinsic energy.

    ``lumped`` replaces ``M`` by the diagonal of its row sums.
    """
    T, D = coefficients(material)
    if D and min(surface.basis_u.degree, surface.basis_v.degree) < 2:
        raise InputError("the bending term D (Δ_S d)² needs degree >= 2 in u and v")
    G = metric.grid(surface, extra_points=2)
    qu, qv = surface.basis_u.degree + 3, surface.basis_v.degree + 3     # points per cell
    cells_u, cells_v = G.index_u[::qu], G.index_v[::qv]
    pattern = Pattern.of(cells_u, cells_v, surface.basis_u.size, surface.basis_v.size, 1)

    def rows_of(rows: slice) -> tuple[metric.Grid, dict[tuple[int, int], Array], Array]:
        p = slice(rows.start * qu, rows.stop * qu)
        part = replace(G, index_u=G.index_u[p], values_u=G.values_u[:, p], weight=G.weight[p],
                       a=G.a[:, p], a2=G.a2[:, p], sqrt_g=G.sqrt_g[p], g_inv=G.g_inv[p],
                       gamma=G.gamma[:, :, p],
                       shapes=None if G.shapes is None else {k: r[p] for k, r in G.shapes.items()})
        return part, metric.shape_derivatives(part), part.weight * part.sqrt_g

    def stiffness(rows: slice) -> Array:
        part, N, dA = rows_of(rows)
        B = []
        if T:
            C = np.linalg.cholesky(part.g_inv)                              # g^αβ = C Cᵀ
            grad = np.stack([N[1, 0], N[0, 1]], axis=2)                     # (Qa, Qv, 2, k)
            Ct_grad = np.einsum("...ji,...jk->...ik", C, grad)
            B.append(np.sqrt(T * dA)[..., None, None] * Ct_grad)
        if D:
            B.append(np.sqrt(D * dA)[..., None, None] * laplace_beltrami(part, N)[..., None, :])
        if not B:
            return np.zeros((rows.stop - rows.start, cells_v.shape[0]) + (N[0, 0].shape[-1],) * 2)
        rows_b = by_cell(np.concatenate(B, axis=2), (qu, qv))             # (A, B, q, r, k)
        rows_b = rows_b.reshape(rows_b.shape[:2] + (-1, rows_b.shape[-1]))
        return np.swapaxes(rows_b, -1, -2) @ rows_b

    def mass(rows: slice) -> Array:
        _, N, dA = rows_of(rows)
        N0 = by_cell(N[0, 0], (qu, qv))                                     # (A, B, q, k)
        return np.swapaxes(N0, -1, -2) @ (by_cell(material.mass * dA, (qu, qv))[..., None] * N0)

    K_full = assemble_cells(pattern, cells_u, cells_v, stiffness)
    M_full = assemble_cells(pattern, cells_u, cells_v, mass)
    if lumped:
        M_full = sp.diags(np.asarray(M_full.sum(axis=1)).ravel(), format="csr")
    return K_full, M_full

