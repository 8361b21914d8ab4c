"""ParaView time series: a ``.pvd`` collection listing one ``.vtu`` mesh per frame."""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path
from xml.sax.saxutils import quoteattr

import numpy as np
from numpy.typing import ArrayLike

from ..surface import Surface
from .atomic import _check_stem, _require_folder, write_text
from .frames import check_frames, check_net, tessellate_frames
from .mesh import write_mesh


def pvd_text(entries: Sequence[tuple[float, str]]) -> str:
    """A ParaView collection file listing ``(time, file name)`` pairs in order."""
    rows = "\n".join(f'    <DataSet timestep="{t!r}" group="" part="0" file={quoteattr(name)}/>'
                     for t, name in entries)
    return ('<?xml version="1.0"?>\n'
            '<VTKFile type="Collection" version="0.1" byte_order="LittleEndian">\n'
            f"  <Collection>\n{rows}\n  </Collection>\n</VTKFile>\n")


def write_time_series(directory: str | os.PathLike[str], stem: str, surface: Surface,
                      rest_net: ArrayLike, times: ArrayLike, nets: ArrayLike,
                      resolution: int = 32) -> Path:
    """Write the motion as a ParaView time series: ``stem.pvd`` plus ``stem_0000.vtu``, ...

    Each frame ``f`` is the surface mesh of ``nets[f]`` with point data
    ``displacement = B_u (P_f - P_rest) B_vᵀ`` (3 components) and
    ``displacement_magnitude = |displacement|``. The ``.pvd`` is written last and lists
    every frame with its time. Returns the ``.pvd`` path.
    """
    folder = _require_folder(directory)
    _check_stem(stem)
    t, P = check_frames(surface, times, nets)
    rest = check_net(surface, rest_net, "rest net")
    X, faces = tessellate_frames(surface, P, resolution)
    X0, _ = tessellate_frames(surface, rest, resolution)
    digits = max(4, len(str(t.size - 1)))
    entries = []
    for f in range(t.size):
        name = f"{stem}_{f:0{digits}d}.vtu"
        d = X[f] - X0
        write_mesh(folder / name, X[f], faces,
                   {"displacement": d, "displacement_magnitude": np.linalg.norm(d, axis=1)})
        entries.append((float(t[f]), name))
    return write_text(folder / f"{stem}.pvd", pvd_text(entries))

