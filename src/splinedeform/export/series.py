"""ParaView time series: a ``.pvd`` collection listing one ``.vtu`` mesh per frame."""

from __future__ import annotations

import os
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from xml.sax.saxutils import quoteattr

import numpy as np
from numpy.typing import ArrayLike

from ..errors import InputError
from ..surface import Surface
from .atomic import _check_stem, write_text
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


def _output_folder(directory: str | os.PathLike[str]) -> Path:
    """``directory``, created with its parents if missing (an error names it otherwise)."""
    folder = Path(directory)
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise InputError(f"cannot create the output folder {folder}: {exc}") from None
    return folder


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
    are one point (:func:`~splinedeform.export.weld.weld`). Each file is written
    atomically and the ``.pvd`` last, listing every frame with its time (see
    docs/outputs.md).

    Parameters
    ----------
    directory : path
        Output folder, created (with its parents) if missing.
    stem : str
        File name stem, without a folder: ``stem.pvd``, ``stem_0000.vtu`` …
    surface : Surface
        The bases the nets are evaluated on.
    rest_net : array_like, shape ``(n_u, n_v, 3)``
        The rest control net ``P_rest`` (the points of every frame).
    times : array_like, shape ``(F,)``
        Non-decreasing time of each frame.
    nets : array_like, shape ``(F, n_u, n_v, 3)``
        The control net ``P_f`` of each frame, e.g. ``solution.control_points(times)``.
    resolution : int
        Samples per parameter direction of each mesh (``resolution²`` points before
        welding).

    Returns
    -------
    Path
        The ``.pvd`` file.
    """
    _check_stem(stem)
    t, P = check_frames(surface, times, nets)
    rest = check_net(surface, rest_net, "rest net")
    folder = _output_folder(directory)
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
