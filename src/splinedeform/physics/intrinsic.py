"""The thin plate under tension measured on the surface (``physics = "intrinsic"``).

For each displacement coordinate ``d`` (x, y and z alike, so one ``n × n`` eigenproblem
still serves all three)::

    E(d) = ½ ∫ T |∇_S d|² dA + ½ ∫ D (Δ_S d)² dA,     kinetic ½ ∫ μ ḋ² dA

with the first fundamental form of the initial surface: ``|∇_S d|² = g^αβ d_,α d_,β``,
``Δ_S d = g^αβ (d_,αβ − Γ^γ_αβ d_,γ)`` (Laplace–Beltrami) and ``dA = √g du dv``. The
Galerkin matrices are assembled on a tensor Gauss grid (:mod:`.metric`), one dense
``(pu pv)²`` block per quadrature point, summed into sparse COO form::

    K_kl = Σ_q w_q √g_q [T g^αβ N_k,α N_l,β + D (Δ_S N_k)(Δ_S N_l)],
    M_kl = Σ_q w_q √g_q μ N_k N_l.

The result depends on the surface, not on its parametrisation, up to discretisation error.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray

from ..errors import InputError
from ..material import Material
from ..surface import Surface
from . import metric

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
    G = metric.grid(surface)
    N = metric.shape_derivatives(G)
    index = metric.global_index(G, surface.basis_v.size)
    size = surface.basis_u.size * surface.basis_v.size
    dA = G.weight * G.sqrt_g
    grad = np.stack([N[1, 0], N[0, 1]])                                    # (2, Qu, Qv, k)
    K = np.zeros(dA.shape + (index.shape[-1],) * 2)
    if T:
        coef = (T * dA)[..., None, None] * G.g_inv                         # (Qu, Qv, 2, 2)
        K += np.einsum("abij,iabk,jabl->abkl", coef, grad, grad)
    if D:
        L = laplace_beltrami(G, N)
        K += (D * dA)[..., None, None] * L[..., :, None] * L[..., None, :]
    M = (material.mass * dA)[..., None, None] * N[0, 0][..., :, None] * N[0, 0][..., None, :]
    K_full, M_full = metric.assemble(index, K, size), metric.assemble(index, M, size)
    if lumped:
        M_full = sp.diags(np.asarray(M_full.sum(axis=1)).ravel(), format="csr")
    return K_full, M_full
