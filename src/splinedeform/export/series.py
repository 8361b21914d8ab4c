"""ParaView time series: a ``.pvd`` collection listing one ``.vtu`` mesh per frame."""

from __future__ import annotations

import os
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from xml.sax.saxutils import quoteattr

import numpy as np
from numpy.typing import ArrayLike

from ..surface import Surface
from .atomic import _check_stem, _require_folder, write_text
from .frames import check_frames, check_net, tessellate_frames
from .mesh import write_mesh
from .weld import weld


def pvd_text(entries: Sequence[tuple[float, str]]) -> str:
    """A ParaView collection file listing ``(time, file name)`` pairs in order."""
    rows = "\n".join(f'    <DataSet timestep="{t!r}" group="" part="0" file={quoteattr(name)}/>'
                     for t, name in entries)
    return ('<?xml version="1.0"?>\n'
            '<VTKFile type="Collection" version="0.1" byte_order="LittleEndian">\n'
            f"  <Collection>\n{rows}\n  </Collection>\n</VTKFile>\n")


def frame_file_names(stem: str, count: int) -> list[str]:
    """Names of the per-frame files: ``stem_0000.vtu`` … (at least 4 digits)."""
    digits = max(4, len(str(count - 1)))
    return [f"{stem}_{f:0{digits}d}.vtu" for f in range(count)]


def write_time_series(directory: str | os.PathLike[str], stem: str, surface: Surface,
                      rest_net: ArrayLike, times: ArrayLike, nets: ArrayLike,
                      resolution: int = 32,
                      fields: Callable[[int], Mapping[str, np.ndarray]] | None = None) -> Path:
    """Write the motion as a ParaView time series: ``stem.pvd`` plus ``stem_0000.vtu``, ...

    Every frame holds the **rest** geometry ``X_0 = B_u P_rest B_vᵀ`` as its points and
    the point data

    * ``displacement`` ``= B_u (P_f - P_rest) B_vᵀ`` (3 components): the deformed surface
      is ``X_0 + displacement``, which is what ParaView's *Warp By Vector* (scale 1) draws;
    * ``displacement_magnitude`` ``= |displacement|``, for colouring;
    * with ``fields``, the arrays ``fields(f)`` of frame ``f``, one row per point of the
      ``surface.sample_parameters(resolution)`` grid in row-major order (e.g. a shell's
      stresses, :func:`splinedeform.export.shell_fields.stress_fields`).

    The points are the same in every frame, so a warp by the field is applied exactly
    once. Grid points that coincide at rest and in every frame (a periodic seam, a pole)
    are one point (:func:`~splinedeform.export.weld.weld`). The ``.pvd`` is written last and lists every frame with its time. Returns the
    ``.pvd`` path.
    """
    folder = _require_folder(directory)
    _check_stem(stem)
    t, P = check_frames(surface, times, nets)
    rest = check_net(surface, rest_net, "rest net")
    X, faces = tessellate_frames(surface, P, resolution)
    X0, _ = tessellate_frames(surface, rest, resolution)
    keep, faces = weld(np.concatenate([X0[None], X]), faces)
    X0, X = X0[keep], X[:, keep]
    names = frame_file_names(stem, t.size)
    for f, name in enumerate(names):
        d = X[f] - X0
        data = {"displacement": d, "displacement_magnitude": np.linalg.norm(d, axis=1)}
        if fields is not None:
            data.update({key: np.asarray(value)[keep] for key, value in fields(f).items()})
        write_mesh(folder / name, X0, faces, data)
    return write_text(folder / f"{stem}.pvd", pvd_text(list(zip(t.tolist(), names))))
