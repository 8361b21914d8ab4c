"""Stress resultants and stresses of the linear Kirchhoff–Love shell at surface points.

From the displacement ``d(u, v)`` of the rest surface (covariant basis ``a_α``, unit normal
``a_3``), the strains of :mod:`.shell` (Voigt ``(·_11, ·_22, 2·_12)``)::

    ε_αβ = ½ (a_α·d_,β + a_β·d_,α),   κ_αβ = d_,αβ·a_3 + a_αβ·δa_3

give the contravariant membrane forces and bending moments::

    n = E t/(1−ν²) H ε,     m = −E t³/(12(1−ν²)) H κ

so that through the thickness (``ζ`` along ``a_3``, ``−t/2 ≤ ζ ≤ t/2``) the strain is
``ε − ζ κ``, the stress ``σ(ζ) = n/t + 12 ζ m/t³``, ``n = ∫ σ dζ`` and ``m = ∫ ζ σ dζ``.
A flat plate with ``a_3 = +z`` has ``m_11 = −D (w_,xx + ν w_,yy)``, the sign of
Timoshenko and Woinowsky-Krieger (sagging under a load along ``a_3`` is positive).
Components are taken in the local orthonormal frame ``e_1 = a_1/|a_1|``,
``e_2 = a_3 × e_1``, ``e_3 = a_3``: ``T_(ij) = T^αβ (e_i·a_α)(e_j·a_β)``. Stresses at the
top (``ζ = t/2``), middle and bottom (``ζ = −t/2``) are ``σ = N/t ± 6 M/t²``; principal
stresses ``(σ_11+σ_22)/2 ± √(((σ_11−σ_22)/2)² + σ_12²)`` and von Mises
``√(σ_11² − σ_11 σ_22 + σ_22² + 3 σ_12²)`` (plane stress).

Transverse shear forces are the divergence of the moments, ``Q^α = m^αβ|_β``
(:func:`transverse_shear`; degree ``>= 3``), ``Q_(i) = Q^α (e_i·a_α)``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InputError
from ..surface import Surface
from .shell import ShellMaterial, constitutive

Array = NDArray[np.float64]
#: through-thickness positions ``ζ / (t/2)`` of the three stress layers
LAYERS = {"top": 1.0, "middle": 0.0, "bottom": -1.0}


@dataclass(frozen=True)
class ShellStresses:
    """Resultants and stresses at points of shape ``S`` (components in the local frame).

    ``N``, ``M`` ``S + (3,)``: ``(N_11, N_22, N_12)`` force per length, ``(M_11, M_22,
    M_12)`` moment per length; ``sigma[layer]`` ``S + (3,)`` for ``"top"``, ``"middle"``,
    ``"bottom"``; ``principal[layer]`` ``S + (2,)`` (larger first); ``von_mises[layer]``
    ``S``; ``normal_displacement`` ``d·a_3`` ``S``; ``frame`` ``S + (3, 3)``, rows
    ``e_1, e_2, e_3``; ``Q`` ``S + (2,)`` the transverse shear forces ``(Q_1, Q_2)`` per
    length (NaN below degree 3). From several nets every field but ``frame`` has a
    leading axis.
    """

    N: Array
    M: Array
    sigma: dict[str, Array]
    principal: dict[str, Array]
    von_mises: dict[str, Array]
    normal_displacement: Array
    frame: Array
    Q: Array

    def maxima(self) -> dict[str, float]:
        """Largest magnitudes: ``|N_ij|``, ``|M_ij|``, ``|Q_i|``, von Mises per layer, ``|d·a_3|``
        (NaN, at poles or below degree 3, skipped)."""
        top = lambda x: float(np.nanmax(np.abs(x), initial=0.0))  # noqa: E731 (NaN: poles)
        out = {f"max |N{ij}|": top(self.N[..., k]) for k, ij in enumerate(("11", "22", "12"))}
        out.update({f"max |M{ij}|": top(self.M[..., k])
                    for k, ij in enumerate(("11", "22", "12"))})
        out.update({f"max |Q{i}|": top(self.Q[..., i - 1]) for i in (1, 2)})
        out.update({f"max von Mises {layer}": top(s) for layer, s in self.von_mises.items()})
        out["max |normal displacement|"] = top(self.normal_displacement)
        return out

    def select(self, index: int | slice) -> ShellStresses:
        """The stresses of net ``index`` of several (the leading axis; ``frame`` is shared)."""
        pick = lambda d: {k: a[index] for k, a in d.items()}  # noqa: E731
        return ShellStresses(self.N[index], self.M[index], pick(self.sigma),
                             pick(self.principal), pick(self.von_mises),
                             self.normal_displacement[index], self.frame, self.Q[index])

    def point_data(self) -> dict[str, Array]:
        """Flat fields for a mesh: resultants, von Mises per layer, normal displacement."""
        flat = self.normal_displacement.size
        data = {"membrane_force": self.N.reshape(flat, 3),
                "bending_moment": self.M.reshape(flat, 3),
                "transverse_shear": self.Q.reshape(flat, 2),
                "normal_displacement": self.normal_displacement.reshape(flat)}
        data.update({f"von_mises_{layer}": s.reshape(flat) for layer, s in self.von_mises.items()})
        return data


def stresses(surface: Surface, material: ShellMaterial, displacement: ArrayLike,
             u: ArrayLike, v: ArrayLike, at_poles: str = "raise") -> ShellStresses:
    """Stresses of a displacement net ``(n_u, n_v, 3)`` at ``u, v`` (broadcast to a shape ``S``).

    Several nets ``(F, n_u, n_v, 3)`` (frames, mode shapes) give every field with a
    leading axis ``F`` (the geometry is evaluated once).

    At a point where the surface degenerates (a pole, ``a_1 × a_2 = 0``) the local frame
    and the stresses are undefined: ``at_poles="raise"`` refuses such a point,
    ``"nan"`` gives NaN there (for output grids that run through a pole).
    """
    net = np.asarray(displacement, dtype=float)
    if net.ndim not in (3, 4) or net.shape[-3:] != surface.shape + (3,):
        raise InputError(f"a displacement net must have shape {surface.shape + (3,)} "
                         f"(or (frames,) + that), got {net.shape}")
    u, v = np.broadcast_arrays(np.asarray(u, dtype=float), np.asarray(v, dtype=float))
    state = _contravariant(surface, material, net, u, v, at_poles)
    n, m, pole, lead = state["n"], state["m"], state["pole"], net.shape[:-3]
    a1, a2, a3 = state["a1"], state["a2"], state["a3"]
    dot = lambda x, y: np.sum(x * y, axis=-1)  # noqa: E731
    t = material.thickness
    e1 = a1 / np.linalg.norm(a1, axis=-1)[..., None]
    e2 = np.cross(a3, e1)
    # c[i, α] = e_i·a_α: T_(ij) = Σ_αβ T^αβ c[i, α] c[j, β]
    c = np.stack([np.stack([dot(e, a1), dot(e, a2)], -1) for e in (e1, e2)], -2)
    N, M = _physical(n, c), _physical(m, c)
    Q = np.einsum("...ia,...a->...i", c, transverse_shear(surface, material, net, u, v, state))
    sigma = {layer: N / t + z * 6 * M / t ** 2 for layer, z in LAYERS.items()}
    normal = dot(state["d0"], a3)
    out = ShellStresses(N, M, sigma, {k: principal(s) for k, s in sigma.items()},
                        {k: von_mises(s) for k, s in sigma.items()}, normal,
                        np.stack([e1, e2, a3], -2), Q)
    if np.any(pole):
        out.frame[pole] = np.nan
        for array in (N, M, Q, normal, *sigma.values(), *out.principal.values(),
                      *out.von_mises.values()):
            where = pole.reshape(pole.shape + (1,) * (array.ndim - len(lead) - pole.ndim))
            np.copyto(array, np.nan, where=np.broadcast_to(where, array.shape))
    return out


def _contravariant(surface: Surface, material: ShellMaterial, net: Array, u: Array,
                   v: Array, at_poles: str) -> dict[str, Array]:
    """``n``, ``m`` (Voigt contravariant, ``lead + S + (3,)``) with the geometry they used."""
    orders = ((1, 0), (0, 1), (2, 0), (1, 1), (0, 2), (0, 0))
    a1, a2, a11, a12, a22 = (surface.derivative(u, v, p, q) for p, q in orders[:5])
    stacked = np.moveaxis(net.reshape((-1,) + net.shape[-3:]), 0, 2)      # (n_u, n_v, F, 3)
    lead = net.shape[:-3]
    d1, d2, d11, d12, d22, d0 = (
        np.moveaxis(surface.derivative(u, v, p, q, control_points=stacked), -2, 0)
        .reshape(lead + u.shape + (3,)) for p, q in orders)
    cross = np.cross(a1, a2)
    sqrt_g = np.linalg.norm(cross, axis=-1)
    scale = max(1.0, float(np.abs(surface.control_points).max()))
    pole = sqrt_g <= 1e-9 * max(float(sqrt_g.max(initial=0.0)), 1e-300) + 1e-14 * scale ** 2
    if np.any(pole) and at_poles != "nan":
        raise InputError("the surface is degenerate (a_1 × a_2 = 0) at some of the given "
                         "parameters (a pole); its stresses are undefined there")
    if np.any(pole):                     # a regular stand-in frame, results set NaN later
        a1, a2 = np.where(pole[..., None], [1.0, 0.0, 0.0], a1), \
            np.where(pole[..., None], [0.0, 1.0, 0.0], a2)
        cross = np.cross(a1, a2)
        sqrt_g = np.linalg.norm(cross, axis=-1)
    a3 = cross / sqrt_g[..., None]
    dot = lambda x, y: np.sum(x * y, axis=-1)  # noqa: E731
    eps = np.stack([dot(a1, d1), dot(a2, d2), dot(a1, d2) + dot(a2, d1)], -1)

    def kappa(second: Array, a_ab: Array) -> Array:
        tilde = a_ab - dot(a_ab, a3)[..., None] * a3
        return (dot(second, a3) + (dot(d1, np.cross(a2, tilde))
                                   + dot(d2, np.cross(tilde, a1))) / sqrt_g)
    kap = np.stack([kappa(d11, a11), kappa(d22, a22), 2 * kappa(d12, a12)], -1)
    g = np.stack([np.stack([dot(a1, a1), dot(a1, a2)], -1),
                  np.stack([dot(a2, a1), dot(a2, a2)], -1)], -2)
    g_inv = np.linalg.inv(g)
    H = constitutive(g_inv, material.nu)
    E, nu, t = material.E, material.nu, material.thickness
    return {"n": E * t / (1 - nu ** 2) * np.einsum("...ij,...j->...i", H, eps),
            "m": -E * t ** 3 / (12 * (1 - nu ** 2)) * np.einsum("...ij,...j->...i", H, kap),
            "a1": a1, "a2": a2, "a3": a3, "a_ab": np.stack([a11, a12, a22]), "g_inv": g_inv,
            "pole": pole, "d0": d0}


#: step of the moments' difference quotients, a fraction of a cell
STEP = 1e-4


def transverse_shear(surface: Surface, material: ShellMaterial, net: Array, u: Array,
                     v: Array, state: dict[str, Array]) -> Array:
    """Contravariant ``Q^α = m^αβ|_β = ∂_β m^αβ + Γ^α_βλ m^λβ + Γ^β_βλ m^αλ``, ``(..., 2)``.

    ``∂_β m`` by second-order difference quotients with a step of :data:`STEP` cells
    (one-sided at the ends of an open direction; a knot line gets the mean of its two
    sides), within ``1e-7`` of the moments' scale. The moments hold second derivatives of
    the displacement, so ``Q`` needs degree ``>= 3`` in both directions; below it is NaN.
    """
    lead = net.shape[:-3]
    if min(surface.basis_u.degree, surface.basis_v.degree) < 3:
        return np.full(lead + u.shape + (2,), np.nan)
    m = _tensor(state["m"])
    derivative = []
    for basis, x, shift in ((surface.basis_u, u, (1.0, 0.0)), (surface.basis_v, v, (0.0, 1.0))):
        h = STEP * basis.length / basis.cells
        offsets = np.broadcast_to(np.array([-1.0, 0.0, 1.0]), x.shape + (3,)).copy()
        weights = np.broadcast_to(np.array([-0.5, 0.0, 0.5]), x.shape + (3,)).copy()
        if not basis.periodic:
            low, high = x - h < 0.0, x + h > basis.length
            offsets[low], weights[low] = (0.0, 1.0, 2.0), (-1.5, 2.0, -0.5)
            offsets[high], weights[high] = (-2.0, -1.0, 0.0), (0.5, -2.0, 1.5)
        total = 0.0
        for k in range(3):
            du, dv = shift[0] * h * offsets[..., k], shift[1] * h * offsets[..., k]
            mk = _tensor(_contravariant(surface, material, net, u + du, v + dv, "nan")["m"])
            total = total + weights[..., k, None, None] * mk / h
        derivative.append(total)
    a_ab, g_inv = state["a_ab"], state["g_inv"]
    contra = np.einsum("...ij,j...c->i...c", g_inv, np.stack([state["a1"], state["a2"]]))
    pair = {(0, 0): 0, (0, 1): 1, (1, 0): 1, (1, 1): 2}
    gamma = np.stack([np.stack([np.stack([np.sum(contra[i] * a_ab[pair[b, l]], -1)
                                          for l in (0, 1)], -1) for b in (0, 1)], -2)
                      for i in (0, 1)], -3)                      # Γ^i_{bl}, S + (2, 2, 2)
    divergence = derivative[0][..., :, 0] + derivative[1][..., :, 1]     # ∂_β m^αβ
    return (divergence + np.einsum("...abl,...lb->...a", gamma, m)
            + np.einsum("...bbl,...al->...a", gamma, m))


def _tensor(T: Array) -> Array:
    """Voigt ``(T^11, T^22, T^12)`` → the symmetric ``2 × 2`` tensor."""
    return np.stack([np.stack([T[..., 0], T[..., 2]], -1),
                     np.stack([T[..., 2], T[..., 1]], -1)], -2)


def _physical(T: Array, c: Array) -> Array:
    """Voigt contravariant ``(T^11, T^22, T^12)`` → local frame ``(T_(11), T_(22), T_(12))``."""
    tensor = np.stack([np.stack([T[..., 0], T[..., 2]], -1),
                       np.stack([T[..., 2], T[..., 1]], -1)], -2)
    local = np.einsum("...ia,...ab,...jb->...ij", c, tensor, c)
    return np.stack([local[..., 0, 0], local[..., 1, 1], local[..., 0, 1]], -1)


def principal(sigma: Array) -> Array:
    """Principal stresses ``(σ_I, σ_II)`` of plane stress ``(σ_11, σ_22, σ_12)``, larger first."""
    mean = 0.5 * (sigma[..., 0] + sigma[..., 1])
    radius = np.hypot(0.5 * (sigma[..., 0] - sigma[..., 1]), sigma[..., 2])
    return np.stack([mean + radius, mean - radius], -1)


def von_mises(sigma: Array) -> Array:
    """``√(σ_11² − σ_11 σ_22 + σ_22² + 3 σ_12²)`` of plane stress."""
    s11, s22, s12 = sigma[..., 0], sigma[..., 1], sigma[..., 2]
    return np.sqrt(np.maximum(s11 ** 2 - s11 * s22 + s22 ** 2 + 3 * s12 ** 2, 0.0))
