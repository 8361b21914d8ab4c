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
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray

from ..errors import InputError
from ..knots import c0_refusal
from ..surface import Surface
from . import metric

Array = NDArray[np.float64]


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
    """Stiffness ``K`` and consistent mass ``M`` over the ``3n`` interleaved displacements."""
    if min(surface.basis_u.degree, surface.basis_v.degree) < 2:
        raise InputError("the Kirchhoff–Love shell needs degree >= 2 in u and v (curvatures)")
    for name, basis in (("u", surface.basis_u), ("v", surface.basis_v)):
        if getattr(basis, "continuity", basis.degree - 1) < 1:
            error = InputError(c0_refusal(basis, name, "the Kirchhoff–Love shell"))
            error.key = "surface"  # type: ignore[attr-defined]
            raise error
    G = metric.grid(surface, extra_points=1)
    q = (surface.basis_u.degree + 2, surface.basis_v.degree + 2)    # Gauss points per cell
    N = metric.shape_derivatives(G)
    index = metric.global_index(G, surface.basis_v.size)[::q[0], ::q[1]]   # one row per cell
    dofs = (3 * index[..., :, None] + np.arange(3)).reshape(index.shape[:2] + (-1,))
    size = 3 * surface.basis_u.size * surface.basis_v.size
    E, nu, t = material.E, material.nu, material.thickness
    dA = G.weight * G.sqrt_g
    H = constitutive(G.g_inv, nu)
    Bm, Bb = strain_operators(G, N)
    shape = Bm.shape[:2] + (3, -1)
    B = np.concatenate([Bm.reshape(shape), Bb.reshape(shape)], axis=2)   # (Qu, Qv, 6, 3k)
    D = np.zeros(B.shape[:2] + (6, 6))
    D[..., :3, :3] = (E * t / (1 - nu ** 2) * dA)[..., None, None] * H
    D[..., 3:, 3:] = (E * t ** 3 / (12 * (1 - nu ** 2)) * dA)[..., None, None] * H
    K = cell_sums(B, D @ B, q)                    # Σ_q Bmᵀ Dm Bm + Bbᵀ Db Bb per cell
    # mass ρt ∫ N_k N_l dA for each coordinate alike: the scalar matrix ⊗ I₃ (interleaved)
    N0 = N[0, 0][..., None, :]
    mass = cell_sums((material.density * t * dA)[..., None, None] * N0, N0, q)
    M = sp.kron(metric.assemble(index, mass, size // 3), sp.identity(3), format="csr")
    return metric.assemble(dofs, K, size), M


def cell_sums(left: Array, right: Array, q: tuple[int, int]) -> Array:
    """``Σ_{points of a cell} leftᵀ right`` for every cell at once, ``(c_u, c_v, k, l)``.

    ``left (Q_u, Q_v, r, k)`` and ``right (Q_u, Q_v, r, l)`` hold the ``q_u × q_v`` Gauss
    points of each cell consecutively (:func:`~splinedeform.quadrature.gauss_points`);
    the points and the ``r`` rows of a cell are stacked into one axis, so each cell's
    block is one matrix product (batched over the cells).
    """
    (Qu, Qv), (qu, qv) = left.shape[:2], q

    def by_cell(A: Array) -> Array:
        A = A.reshape((Qu // qu, qu, Qv // qv, qv) + A.shape[2:]).swapaxes(1, 2)
        return A.reshape(A.shape[:2] + (qu * qv * A.shape[-2], A.shape[-1]))
    return np.swapaxes(by_cell(left), -1, -2) @ by_cell(right)
