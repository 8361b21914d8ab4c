"""Outputs of a body: every patch's deformed net in one file.

* ``.3dm``: one Brep, a face per patch, its edges joined where the patches meet, in the
  body's unit (:func:`splinedeform.cad.write_3dm`, :mod:`splinedeform.cad_brep_3dm`);
* STEP / IGES: one B-spline face per patch in one file, bounded by its trim loops where
  it is trimmed and reversed where the body's orientation says so, sewn into a shell
  where the patches meet (:func:`splinedeform.cad_step.write_step`);
* a welded mesh (``.vtu``, ``.vtk``, ``.obj``, ``.stl``, ``.ply``): each patch sampled on
  its ``r × r`` parameter grid, ``X_k = B_u P_k B_vᵀ`` (:func:`.frames.tessellate_frames`),
  the grids put side by side and their points merged where they coincide at rest and in
  every frame (:func:`.weld.weld`): the points of a shared edge or a closed seam are one
  point, so the mesh is connected across the body. A patch whose Brep face is reversed
  (``orientation`` ``-1``, :attr:`splinedeform.body.Body.orientation`) has its triangles
  wound the other way, so every triangle's normal ``(b - a) × (c - a)`` (and the OBJ's
  vertex normals) points along the Brep's outward normal;
* a ParaView series (``.pvd`` + one welded ``.vtu`` per frame), the rest points with the
  point data ``displacement`` and ``displacement_magnitude`` as
  :func:`.series.write_time_series` writes for one surface, and ``patch`` (the index of
  the patch a point was first sampled on).
"""

from __future__ import annotations

import os
import warnings
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InputError, InputWarning
from ..surface import Surface
from .atomic import _check_stem, write_text
from .frames import check_frames, check_net, tessellate_frames
from .mesh import write_mesh
from .series import _output_folder, frame_file_names, pvd_text
from .weld import weld


def _check_body(surfaces: Sequence[Surface], nets: Sequence[ArrayLike], what: str
                ) -> list[NDArray[np.float64]]:
    """One net per surface, each checked (:func:`.frames.check_net`)."""
    if len(nets) != len(surfaces) or not surfaces:
        raise InputError(f"a body of {len(surfaces)} patch(es) needs as many {what}s, got "
                         f"{len(nets)}")
    return [check_net(s, P, f"{what} of patch {k}") for k, (s, P) in
            enumerate(zip(surfaces, nets))]


def body_patches(surfaces: Sequence[Surface], nets: Sequence[ArrayLike],
                 units: str | None = None) -> list:
    """The NURBS patch of every surface with its net (same degrees, knots, weights)."""
    from dataclasses import replace

    from ..cad import patch_from_surface

    return [replace(patch_from_surface(s, P), units=units)
            for s, P in zip(surfaces, _check_body(surfaces, nets, "control net"))]


def write_body_3dm(path: str | os.PathLike, surfaces: Sequence[Surface],
                   nets: Sequence[ArrayLike], names: Sequence[str] | None = None,
                   units: str | None = None, body: Any = None, name: str = "body") -> Path:
    """Every patch with its net as a face of one Brep named ``name`` in a ``.3dm`` file,
    its edges joined where the patches meet, in ``units`` (the file's
    ``ModelUnitSystem``); the faces' names (default: the surfaces') are the Brep's user
    strings ``splinedeform.face k``. The topology is ``body``'s (a
    :class:`~splinedeform.body.Body` of ``surfaces``), found from the surfaces when not
    given; where no Brep can be formed, one named NURBS surface per patch, with a warning
    (:func:`splinedeform.cad.write_3dm`)."""
    from ..body import Body
    from ..cad import write_3dm
    from ..cad_brep_3dm import BrepTopology

    names = [s.name for s in surfaces] if names is None else list(names)
    patches = body_patches(surfaces, nets, units)
    trims = [getattr(s, "trim", None) for s in surfaces]
    topology = None
    try:
        topology = BrepTopology.of(Body(surfaces) if body is None else body, name)
    except InputError as exc:
        warnings.warn(f"the body is written as {len(patches)} separate surfaces, not one "
                      f"Brep: its topology could not be found: {exc}", InputWarning,
                      stacklevel=2)
    return write_3dm(path, patches, names=names, units=units, body=topology,
                     trims=trims if any(t is not None for t in trims) else None)


def write_body_step(path: str | os.PathLike, surfaces: Sequence[Surface],
                    nets: Sequence[ArrayLike], units: str | None = None,
                    shell: bool = True, orientation: Sequence[int] | None = None) -> Path:
    """Every patch with its net as a B-spline face of one STEP or IGES file (by the
    suffix), in ``units``: a trimmed surface (``surface.trim``) bounded by its trim loops,
    a patch of ``orientation`` ``-1`` (:attr:`splinedeform.body.Body.orientation`)
    reversed; with ``shell`` the faces are sewn where they meet into one shell
    (:func:`splinedeform.cad_step.write_step`)."""
    from ..cad_step import write_step

    return write_step(path, body_patches(surfaces, nets, units), units=units, shell=shell,
                      trims=[s.trim for s in surfaces], orientation=orientation)


def welded_body(surfaces: Sequence[Surface], frames: Sequence[ArrayLike], resolution: int = 32,
                orientation: Sequence[int] = ()
                ) -> tuple[NDArray[np.float64], NDArray[np.int64], NDArray[np.int64]]:
    """The body's welded mesh in every frame (see the module docstring).

    Parameters
    ----------
    surfaces : sequence of Surface
    frames : sequence of array_like, shape ``(G, n_u, n_v, 3)`` each
        The ``G`` nets of each patch (the same ``G`` for all).
    resolution : int
        Samples per direction of each patch.
    orientation : sequence of {+1, -1}, optional
        Per patch ``-1`` where its triangles are wound against ``x_u × x_v`` (a reversed
        Brep face); empty: ``+1`` everywhere.

    Returns
    -------
    points : ndarray, shape ``(G, N, 3)``
    faces : ndarray of int, shape ``(M, 3)``
    patch : ndarray of int, shape ``(N,)``
        The patch each point was first sampled on.
    """
    X, faces, patch, _ = welded_body_points(surfaces, frames, resolution, orientation)
    return X, faces, patch


def _signs(orientation: Sequence[int], count: int) -> tuple[int, ...]:
    """One sign per patch (:func:`splinedeform.body.body._orientation`), ``+1`` everywhere
    when ``orientation`` is empty."""
    from ..body.body import _orientation

    return _orientation(orientation if len(orientation) else None, count)


def welded_body_points(surfaces: Sequence[Surface], frames: Sequence[ArrayLike],
                       resolution: int = 32, orientation: Sequence[int] = ()
                       ) -> tuple[NDArray[np.float64], NDArray[np.int64], NDArray[np.int64],
                                  NDArray[np.int64]]:
    """:func:`welded_body` and ``keep``: the index of each welded point among the patches'
    grid points put side by side (patch after patch, each row-major), so that values
    sampled on those grids (a shell's stresses) follow the points."""
    blocks, faces, owner, offset = [], [], [], 0
    signs = _signs(orientation, len(surfaces))
    for k, (surface, P) in enumerate(zip(surfaces, frames)):
        X, F = tessellate_frames(surface, P, resolution)
        blocks.append(X)
        faces.append((F if signs[k] > 0 else F[:, [0, 2, 1]]) + offset)
        owner.append(np.full(X.shape[1], k))
        offset += X.shape[1]
    X = np.concatenate(blocks, axis=1)
    keep, welded = weld(X, np.concatenate(faces))
    return X[:, keep], welded, np.concatenate(owner)[keep], keep


def write_body_mesh(path: str | os.PathLike, surfaces: Sequence[Surface],
                    nets: Sequence[ArrayLike], rest_nets: Sequence[ArrayLike] | None = None,
                    resolution: int = 32, orientation: Sequence[int] = ()) -> Path:
    """The deformed body as one welded mesh (the format by the suffix, see
    :func:`.mesh.write_mesh`), with ``patch`` and, given the rest nets, ``displacement``
    (deformed minus rest) as point data; points are welded where they coincide in both,
    triangles wound along each face's ``orientation`` (module docstring)."""
    P = _check_body(surfaces, nets, "control net")
    rest = P if rest_nets is None else _check_body(surfaces, rest_nets, "rest net")
    X, faces, patch = welded_body(surfaces, [np.stack([r, p]) for r, p in zip(rest, P)],
                                  resolution, orientation)
    data: dict[str, NDArray] = {"patch": patch.astype(float)}
    if rest_nets is not None:
        data["displacement"] = X[1] - X[0]
    return write_mesh(path, X[1], faces, data)


def welded_motion(surfaces: Sequence[Surface], rest_nets: Sequence[ArrayLike],
                  times: ArrayLike, nets: Sequence[ArrayLike], resolution: int = 32,
                  orientation: Sequence[int] = (), extra: Sequence[ArrayLike] = ()
                  ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.int64],
                             NDArray[np.int64], NDArray[np.int64]]:
    """``(times, points, faces, patch, keep)``: the body's welded mesh
    (:func:`welded_body_points`) at rest (``points[0]``) and in the frames ``nets[k]``
    ``(F, n_u, n_v, 3)`` of each patch ``k`` at ``times`` (``points[1:]``), checked;
    ``keep`` indexes the welded points among the patches' grids side by side. ``extra[k]``
    ``(E, n_u, n_v, 3)`` are more nets of patch ``k`` welded with the frames (a modes
    solve's ``P_rest + D_k``), their points after the frames' (``points[1 + F:]``)."""
    rest = _check_body(surfaces, rest_nets, "rest net")
    if len(nets) != len(surfaces):
        raise InputError(f"a body of {len(surfaces)} patch(es) needs as many frame sets, "
                         f"got {len(nets)}")
    checked = [check_frames(s, times, P) for s, P in zip(surfaces, nets)]
    more = [np.asarray(e, dtype=float) for e in extra] or \
        [np.zeros((0, *s.shape, 3)) for s in surfaces]
    X, faces, patch, keep = welded_body_points(
        surfaces, [np.concatenate([r[None], P, e]) for r, (_, P), e in zip(rest, checked, more)],
        resolution, orientation)
    return checked[0][0], X, faces, patch, keep


def write_body_series(directory: str | os.PathLike, stem: str, surfaces: Sequence[Surface],
                      rest_nets: Sequence[ArrayLike], times: ArrayLike,
                      nets: Sequence[ArrayLike], resolution: int = 32,
                      fields: Callable[[int], Mapping[str, NDArray]] | None = None,
                      orientation: Sequence[int] = ()) -> Path:
    """The body's motion as a ParaView series ``stem.pvd`` + ``stem_0000.vtu`` … (see the
    module docstring); ``nets[k]`` has shape ``(F, n_u, n_v, 3)``, the frames of patch
    ``k`` at ``times``. With ``fields``, the arrays ``fields(f)`` of frame ``f`` too, one
    row per point of the patches' grids side by side (a shell's stresses). Returns the
    ``.pvd`` file (written last)."""
    _check_stem(stem)
    t, X, faces, patch, keep = welded_motion(surfaces, rest_nets, times, nets, resolution,
                                             orientation)
    folder = _output_folder(directory)
    names = frame_file_names(stem, t.size)
    for f, name in enumerate(names):
        d = X[f + 1] - X[0]
        data = {"displacement": d, "displacement_magnitude": np.linalg.norm(d, axis=1),
                "patch": patch.astype(float)}
        if fields is not None:
            data.update({key: np.asarray(value)[keep] for key, value in fields(f).items()})
        write_mesh(folder / name, X[0], faces, data)
    return write_text(folder / f"{stem}.pvd", pvd_text(list(zip(t.tolist(), names))))
