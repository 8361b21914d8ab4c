"""Vibration modes for ParaView: one ``.vtu`` with a displacement field per mode, of one
surface (:func:`write_mode_fields`) or of every face of a body (:func:`write_body_mode_fields`)."""

from __future__ import annotations

import os
from collections.abc import Sequence
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


def write_body_mode_fields(path: str | os.PathLike[str], surfaces: Sequence[Surface],
                           mode_nets: Sequence[ArrayLike], resolution: int = 32,
                           orientation: Sequence[int] = ()) -> Path:
    """:func:`write_mode_fields` of a body: every face in one welded mesh.

    ``mode_nets[p]`` ``(K, n_u, n_v, 3)`` holds the modes of patch ``p`` as control-net
    displacements. The points are the rest geometry of every patch sampled on its ``r × r``
    grid and welded where the patches meet at rest and in every mode
    (:func:`.body.welded_body_points`, triangles wound along ``orientation``); the point
    data ``mode_k = X(P_rest + D_k) − X(P_rest)`` is mode ``k`` as a displacement and
    ``patch`` the patch each point was first sampled on.
    """
    from .body import _check_body, welded_body_points

    rests = _check_body(surfaces, [s.control_points for s in surfaces], "rest net")
    if len(mode_nets) != len(surfaces):
        raise InputError(f"a body of {len(surfaces)} patch(es) needs as many mode sets, got "
                         f"{len(mode_nets)}")
    D = [np.asarray(d, dtype=float) for d in mode_nets]
    for k, (s, d) in enumerate(zip(surfaces, D)):
        if d.ndim != 4 or d.shape[0] == 0 or d.shape[1:] != (*s.shape, 3) \
                or d.shape[0] != D[0].shape[0] or not np.all(np.isfinite(d)):
            raise InputError(f"the modes of patch {k} must be a finite array (K, {s.shape[0]}, "
                             f"{s.shape[1]}, 3) with the same K >= 1 for every patch, got "
                             f"shape {d.shape}")
    X, faces, patch, _ = welded_body_points(
        surfaces, [np.concatenate([r[None], r[None] + d]) for r, d in zip(rests, D)],
        resolution, orientation)
    data = {name: X[k + 1] - X[0] for k, name in enumerate(mode_field_names(len(D[0])))}
    data["patch"] = patch.astype(float)
    return write_mesh(path, X[0], faces, data)
