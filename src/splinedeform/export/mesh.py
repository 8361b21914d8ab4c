"""Triangle meshes for other programs (.obj, .stl, .ply, .vtu, .vtk).

OBJ is written here (with vertex normals, which meshio's writer does not reference from
the faces); the others through meshio, imported lazily (it is part of the ``tool`` extra).
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InputError
from .atomic import write_with
from .weld import vertex_normals

MESH_FORMATS: tuple[str, ...] = (".obj", ".stl", ".ply", ".vtu", ".vtk")
_MESHIO_OPTIONS: dict[str, dict[str, Any]] = {
    ".stl": {"binary": True}, ".ply": {"binary": True}, ".vtk": {"binary": True},
    ".vtu": {"binary": True, "compression": None}}


def _check_mesh(vertices: ArrayLike, faces: ArrayLike
                ) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    V = np.asarray(vertices, dtype=float)
    Fc = np.asarray(faces)
    if V.ndim != 2 or V.shape[1] != 3 or V.shape[0] == 0:
        raise InputError(f"vertices must have shape (N, 3) with N >= 1, got {V.shape}")
    if not np.all(np.isfinite(V)):
        raise InputError("vertices contain non-finite values")
    if Fc.ndim != 2 or Fc.shape[1] != 3 or not np.issubdtype(Fc.dtype, np.integer):
        raise InputError(f"faces must be an integer array of shape (M, 3), got "
                         f"{Fc.dtype} {Fc.shape}")
    if Fc.size and (Fc.min() < 0 or Fc.max() >= V.shape[0]):
        raise InputError(f"face indices must lie in [0, {V.shape[0] - 1}], got "
                         f"[{Fc.min()}, {Fc.max()}]")
    return V, Fc.astype(np.int64)


def _check_point_data(point_data: Mapping[str, ArrayLike] | None, n: int
                      ) -> dict[str, NDArray[np.float64]]:
    out: dict[str, NDArray[np.float64]] = {}
    for name, values in (point_data or {}).items():
        a = np.asarray(values, dtype=float)
        if not isinstance(name, str) or not name:
            raise InputError(f"point data names must be non-empty strings, got {name!r}")
        if a.ndim not in (1, 2) or a.shape[0] != n:
            raise InputError(f"point data {name!r} must have shape ({n},) or ({n}, c), "
                             f"got {a.shape}")
        out[name] = a
    return out


def _ply_point_data(point_data: dict[str, NDArray[np.float64]]) -> dict[str, NDArray[np.float64]]:
    """PLY holds scalar vertex properties only: vectors become ``name_0, name_1, ...``."""
    out: dict[str, NDArray[np.float64]] = {}
    for name, a in point_data.items():
        if a.ndim == 1:
            out[name] = a
        else:
            out.update({f"{name}_{c}": a[:, c] for c in range(a.shape[1])})
    return out


def write_obj(path: str | os.PathLike[str], vertices: ArrayLike, faces: ArrayLike,
              normals: ArrayLike | None = None) -> Path:
    """Wavefront OBJ with vertex normals: ``v x y z``, ``vn nx ny nz``, ``f a//a b//b c//c``.

    Coordinates are written with 17 significant digits (they read back exactly).
    ``normals`` defaults to :func:`~splinedeform.export.weld.vertex_normals` (area-weighted
    face normals); faces keep their orientation, so normals follow ``x_u × x_v``.
    """
    V, Fc = _check_mesh(vertices, faces)
    N = vertex_normals(V, Fc) if normals is None else np.asarray(normals, dtype=float)
    if N.shape != V.shape or not np.all(np.isfinite(N)):
        raise InputError(f"normals must be a finite array of shape {V.shape}, got {N.shape}")
    corners = np.repeat(Fc + 1, 2, axis=1)               # a//a b//b c//c (1-based)

    def save(tmp: Path) -> None:
        with open(tmp, "w", encoding="ascii") as fh:
            fh.write("# splinedeform surface mesh: vertices, vertex normals, triangles\n")
            np.savetxt(fh, V, fmt="v %.17g %.17g %.17g")
            np.savetxt(fh, N, fmt="vn %.17g %.17g %.17g")
            np.savetxt(fh, corners, fmt="f %d//%d %d//%d %d//%d")

    return write_with(path, save)


def write_mesh(path: str | os.PathLike[str], vertices: ArrayLike, faces: ArrayLike,
               point_data: Mapping[str, ArrayLike] | None = None) -> Path:
    """Write a triangle mesh; the format follows the suffix (.obj, .stl, .ply, .vtu, .vtk).

    Parameters
    ----------
    path : path-like
        Target file; written atomically.
    vertices : array_like, shape ``(N, 3)``
    faces : array_like of int, shape ``(M, 3)``
    point_data : mapping of name to ``(N,)`` or ``(N, c)`` arrays, optional
        Kept by .vtu/.vtk as is and by .ply as scalar properties (vectors split into
        ``name_0, name_1, ...``); OBJ and STL cannot hold it and drop it. OBJ gets
        vertex normals (:func:`write_obj`). STL stores float32 coordinates.
    """
    target = Path(path)
    suffix = target.suffix.lower()
    if suffix not in MESH_FORMATS:
        raise InputError(f"mesh format is chosen by the file suffix, one of {MESH_FORMATS}; "
                         f"got {target.name!r}")
    V, Fc = _check_mesh(vertices, faces)
    data = _check_point_data(point_data, V.shape[0])
    if suffix == ".obj":
        return write_obj(target, V, Fc)
    import meshio

    if suffix == ".stl":
        data = {}
    elif suffix == ".ply":
        data = _ply_point_data(data)
    cells = Fc.astype(np.int32) if suffix == ".ply" and V.shape[0] < 2**31 else Fc
    mesh = meshio.Mesh(V, [("triangle", cells)], point_data=data)
    options = _MESHIO_OPTIONS.get(suffix, {})
    return write_with(target, lambda tmp: meshio.write(tmp, mesh, file_format=suffix[1:],
                                                       **options))
