"""Validation of frames and the tessellation of many control nets on one grid.

Meshes of a control net ``P`` are the surface sampled on a ``r × r`` parameter grid,
``X[i, j] = Σ_kl p_kl b_k(u_i) b_l(v_j)``, i.e. ``X = B_u P B_vᵀ`` per coordinate; for a
whole motion the collocation matrices ``B_u``, ``B_v`` are built once
(:func:`tessellate_frames`).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InputError
from ..rational import grid_nets
from ..surface import Surface, grid_faces

# -- validation of frames ----------------------------------------------------------
def check_net(surface: Surface, net: ArrayLike, what: str = "control net") -> NDArray[np.float64]:
    """``net`` as a finite float array of shape ``(n_u, n_v, 3)`` matching ``surface``."""
    expected = (*surface.shape, 3)
    try:
        P = np.asarray(net, dtype=float)
    except (TypeError, ValueError) as exc:
        raise InputError(f"{what} must be a numeric array of shape {expected}: {exc}") from None
    if P.shape != expected:
        raise InputError(f"{what} must have shape {expected} (n_u, n_v, 3), got {P.shape}")
    if not np.all(np.isfinite(P)):
        raise InputError(f"{what} contains non-finite values")
    return P


def check_frames(surface: Surface, times: ArrayLike, nets: ArrayLike
                 ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Validate a motion: ``times (F,)`` finite and non-decreasing, ``nets (F, n_u, n_v, 3)``."""
    if not isinstance(surface, Surface):
        raise InputError(f"surface must be a splinedeform.Surface, got {type(surface).__name__}")
    try:
        t = np.asarray(times, dtype=float)
        P = np.asarray(nets, dtype=float)
    except (TypeError, ValueError) as exc:
        raise InputError(f"times and nets must be numeric arrays: {exc}") from None
    if t.ndim != 1 or t.size == 0:
        raise InputError(f"times must be a non-empty 1-D array (F,), got shape {t.shape}")
    if not np.all(np.isfinite(t)) or np.any(np.diff(t) < 0):
        raise InputError("times must be finite and non-decreasing")
    expected = (t.size, *surface.shape, 3)
    if P.shape != expected:
        raise InputError(f"nets must have shape {expected} (F, n_u, n_v, 3) for {t.size} "
                         f"time(s), got {P.shape}")
    if not np.all(np.isfinite(P)):
        raise InputError("nets contain non-finite values")
    return t, P


# -- tessellation of many frames ---------------------------------------------------------
def tessellate_frames(surface: Surface, nets: ArrayLike, resolution: int = 32
                      ) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    """Meshes of many control nets on one parameter grid, without re-assembly per frame.

    ``X_f = B_u P_f B_vᵀ`` per coordinate with ``(B_u)_ik = b_k(u_i)``, ``(B_v)_jl = b_l(v_j)``
    built once (:func:`splinedeform.rational.grid_nets`, general weights included).
    ``nets`` has shape ``(..., n_u, n_v, 3)``; returns vertices ``(..., r_u r_v, 3)``
    (row-major grid, as :meth:`Surface.tessellate`) and faces. A trimmed surface gives
    the grid clipped to its trim loops instead
    (:func:`splinedeform.trim.tessellate.clipped_grid`): the vertices inside and those
    on the loops, ``X_f = E P_f`` with the sparse ``E_{q,(k,l)} = b_k(u_q) b_l(v_q)``.
    """
    if isinstance(resolution, bool) or not isinstance(resolution, (int, np.integer)):
        raise InputError(f"resolution must be an integer >= 2, got {resolution!r}")
    u, v = surface.sample_parameters(int(resolution))
    if surface.trim is not None:
        return _clipped_frames(surface, nets, u, v)
    P = np.asarray(nets, dtype=float)
    if P.shape[-3:] != (*surface.shape, 3):
        raise InputError(f"control nets must end in shape {(*surface.shape, 3)}, got {P.shape}")
    X = grid_nets(surface, u, v, P)
    return X.reshape(*P.shape[:-3], u.size * v.size, 3), grid_faces(u.size, v.size)



def _clipped_frames(surface: Surface, nets: ArrayLike, u: NDArray[np.float64],
                    v: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    """:func:`tessellate_frames` of a trimmed surface: one sparse product for all frames."""
    from ..trim.tessellate import surface_grid

    P = np.asarray(nets, dtype=float)
    if P.shape[-3:] != (*surface.shape, 3):
        raise InputError(f"control nets must end in shape {(*surface.shape, 3)}, got {P.shape}")
    uv, faces = surface_grid(surface, u, v)
    E = surface.evaluation_matrix(uv[:, 0], uv[:, 1])
    lead = P.shape[:-3]
    flat = np.moveaxis(P.reshape(-1, E.shape[1], 3), 0, 1).reshape(E.shape[1], -1)
    X = np.moveaxis(np.asarray(E @ flat).reshape(len(uv), -1, 3), 1, 0)
    return X.reshape(*lead, len(uv), 3), faces
