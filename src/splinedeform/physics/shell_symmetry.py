"""The slope condition of a shell's symmetry edge, for any parametrisation.

A displacement field symmetric about the plane ``x_a = const`` has ``d_a = 0`` on the plane
and no slope across it: ``∂_ν d_b = 0`` for ``b ≠ a``, ``ν = e_a`` the plane's normal, which
lies in the surface's tangent plane where the surface crosses the plane at right angles
(the only way a smooth surface can be mirror symmetric). In the parameters ``ν`` is
``α a_u + β a_v`` (``(α, β)`` from the 2 × 2 metric), so on an edge ``u = 0``::

    α(v) d_b,u(0, v) + β(v) d_b,v(0, v) = 0.

``β = 0`` where the ``u`` lines cross the plane perpendicularly; an oblique map has
``β ≠ 0`` and the slope along the ``u`` lines is not the slope across the plane. The
condition is imposed weakly along the edge, against every function ``B_k`` of the basis
along it (Gauss quadrature, ``n + 3`` points per cell)::

    Σ_q w_q s_q [α d_b,u + β d_b,v](0, v_q) B_k(v_q) = 0,

with the scale ``s = |a_u|`` keeping the rows bounded at a pole (where ``a_u → 0``). Where
``β = 0`` it is the strong condition (the slope is a spline in ``v`` and the weighted Gram
matrix is positive definite). The rows ``C = b'(0) ⊗ G_α + b(0) ⊗ G'_β`` over the control
points are a Kronecker sum, sparse. With general weights
(:attr:`~splinedeform.Surface.net_weights`) the slopes are the rational basis' own,
``C = B_0ᵀ diag(w s α) E_cross + B_0ᵀ diag(w s β) E_along`` with the evaluation matrices
``E`` of ``∂ R_kl`` at the edge's Gauss points (:meth:`~splinedeform.Surface.evaluation_matrix`).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray

from ..errors import InputError
from ..quadrature import gauss_points
from ..surface import Surface

Array = NDArray[np.float64]
TILT_TOL = 1e-3
"""Largest accepted angle (radians) between the plane's normal and the surface's tangent
plane on a symmetry edge: beyond it the mirrored surface would kink at the plane."""


def slope_rows(surface: Surface, edge: str, axis: int) -> sp.csr_matrix:
    """Rows ``C`` over the interleaved ``3n`` dofs: ``∂_ν d_b = 0`` weakly for ``b ≠ axis``."""
    across_u = edge[0] == "u"
    across, along = ((surface.basis_u, surface.basis_v) if across_u
                     else (surface.basis_v, surface.basis_u))
    x0 = np.array([0.0 if edge[1] == "0" else across.length])
    s, w = gauss_points(along, along.degree + 3)
    u, v = (np.full_like(s, x0[0]), s) if across_u else (s, np.full_like(s, x0[0]))
    a_u, a_v = surface.derivative(u, v, 1, 0), surface.derivative(u, v, 0, 1)
    a_cross, a_along = (a_u, a_v) if across_u else (a_v, a_u)
    g = np.stack([np.stack([np.sum(a_cross * a_cross, -1), np.sum(a_cross * a_along, -1)], -1),
                  np.stack([np.sum(a_along * a_cross, -1), np.sum(a_along * a_along, -1)], -1)],
                 -2)
    rhs = np.stack([a_cross[:, axis], a_along[:, axis]], -1)
    coef = np.linalg.solve(g, rhs[..., None])[..., 0]      # ν ≈ α a_cross + β a_along
    nu = coef[:, :1] * a_cross + coef[:, 1:] * a_along
    tilt = np.arccos(np.clip(np.linalg.norm(nu, axis=-1), 0.0, 1.0))
    if tilt.max() > TILT_TOL:
        i = int(np.argmax(tilt))
        raise InputError(
            f"symmetry edge {edge} of {surface.name!r}: the surface meets its symmetry plane "
            f"{'xyz'[axis]} = const at {90 - np.degrees(tilt[i]):.3g}° (at parameter "
            f"{s[i]:.4g} along the edge), not at right angles, so its mirror image would "
            f"kink there (at most {np.degrees(TILT_TOL):.2g}° off is accepted)")
    scale = np.linalg.norm(a_cross, axis=-1)
    alpha, beta = w * scale * coef[:, 0], w * scale * coef[:, 1]
    B0 = along.matrix(s, 0).toarray()
    if surface.net_weights is not None:           # ∂R_kl on the edge: the quotient rule
        E_u, E_v = (surface.evaluation_matrix(u, v, *order) for order in ((1, 0), (0, 1)))
        E_cross, E_along = (E_u, E_v) if across_u else (E_v, E_u)
        C = sp.csr_matrix(B0.T @ (sp.diags(alpha) @ E_cross + sp.diags(beta) @ E_along))
    else:
        B1 = along.matrix(s, 1).toarray()
        G_alpha = B0.T @ (alpha[:, None] * B0)                        # [k, j]
        G_beta = B0.T @ (beta[:, None] * B1)
        b0, b1 = across.matrix(x0, 0), across.matrix(x0, 1)
        if across_u:
            C = sp.kron(b1, G_alpha) + sp.kron(b0, G_beta)           # over (i n_v + j)
        else:
            C = sp.kron(G_alpha, b1) + sp.kron(G_beta, b0)
        C = sp.csr_matrix(C)
    n = C.shape[1]
    rows = []
    for b in np.delete(np.arange(3), axis):
        place = sp.csr_matrix((np.ones(n), (np.arange(n), 3 * np.arange(n) + b)),
                              shape=(n, 3 * n))
        rows.append(C @ place)
    return sp.vstack(rows).tocsr()
