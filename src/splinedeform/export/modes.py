"""Vibration modes for ParaView: one ``.vtu`` with a displacement field per mode."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike

from ..errors import InputError
from ..surface import Surface
from .frames import check_net, tessellate_frames
from .mesh import write_mesh
from .weld import weld


def mode_field_names(count: int) -> list[str]:
    """Point-data names of the modes: ``mode_1``, ``mode_2``, …"""
    return [f"mode_{k}" for k in range(1, count + 1)]


def write_mode_fields(path: str | os.PathLike[str], surface: Surface, mode_nets: ArrayLike,
                      resolution: int = 32) -> Path:
    """Write the rest surface with one displacement field per mode (``.vtu`` / ``.vtk``).

    The points are the rest geometry ``X_0 = B_u P_rest B_vᵀ``; the point data
    ``mode_k = B_u D_k B_vᵀ`` (3 components) is mode ``k`` as a displacement, from the
    control-net displacement ``D_k`` (``mode_nets (K, n_u, n_v, 3)``). ParaView's *Warp By
    Vector* with ``mode_k`` draws the mode; a scale factor ``s sin(2π φ)`` animates it.
    Grid points that coincide at rest and in every mode (seams, poles) are one point.
    """
    D = np.asarray(mode_nets, dtype=float)
    if D.ndim != 4 or D.shape[0] == 0 or D.shape[1:] != (*surface.shape, 3) \
            or not np.all(np.isfinite(D)):
        raise InputError(f"mode nets must be a finite array (K, {surface.shape[0]}, "
                         f"{surface.shape[1]}, 3) with K >= 1, got shape {D.shape}")
    rest = check_net(surface, surface.control_points, "rest net")
    X0, faces = tessellate_frames(surface, rest, resolution)
    # the displacement fields are linear in the net: tessellate D_k as nets of their own
    fields, _ = tessellate_frames(surface, D, resolution)
    keep, faces = weld(np.concatenate([X0[None], X0[None] + fields]), faces)
    data = {name: fields[k, keep] for k, name in enumerate(mode_field_names(len(D)))}
    return write_mesh(path, X0[keep], faces, data)
