"""The sculpted shape as a file the page downloads: ``.3dm``, OBJ or a control-net JSON.

The shape is the control net of the page's modal state ``q`` (``3 k`` numbers, mode-major),
``P + T Φ_net q`` (:func:`.history.baked_net`, the net a bake would make the rest shape),
written by the project's own writers: :func:`splinedeform.cad.write_3dm` (a NURBS surface
on the model's knot vectors, weights 1 or ``a_i b_j``), :func:`splinedeform.export.mesh.
write_obj` (the surface sampled on the page's grid, clipped to its trims, vertex normals) and
:func:`splinedeform.export.nets.write_control_nets` (the project's net file, which
``shape = "file"`` reads back). Each is written to a private temporary folder and its
bytes returned; nothing is written beside the save.

A body keeps every face: the ``.3dm`` holds one Brep of the body's faces, its edges joined,
in the body's unit (:func:`splinedeform.export.body.write_body_3dm`), the OBJ one mesh
welded across the shared edges (:func:`splinedeform.export.body.write_body_mesh`), the net
file one net per face (``stem-face-k.json``, bundled as ``.zip``).
"""

from __future__ import annotations

import re
import tempfile
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from .history import baked_nets
from .modal import SculptBasis

#: format -> (suffix, media type)
SHAPE_FORMATS = {"3dm": (".3dm", "application/octet-stream"),
                 "obj": (".obj", "text/plain; charset=ascii"),
                 "json": (".json", "application/json")}


def file_stem(title: str) -> str:
    """A file name stem from a title: letters, digits, ``._-`` (others become ``_``)."""
    return re.sub(r"[^A-Za-z0-9._-]+", "_", title).lstrip("._") or "sculpt"


def shape_file(basis: SculptBasis, q: NDArray[np.float64], fmt: str, title: str
               ) -> tuple[bytes, str, str]:
    """``(content, file name, media type)`` of the shape of modal state ``q`` in ``fmt``."""
    nets = baked_nets(basis, q)
    stem = file_stem(title) + "-shape"
    with tempfile.TemporaryDirectory(prefix="splinedeform-shape-") as folder:
        if basis.is_body:
            path = _body_file(basis, nets, fmt, Path(folder), stem, title)
            media = "application/zip" if path.suffix == ".zip" else SHAPE_FORMATS[fmt][1]
        else:
            path = _surface_file(basis, nets[0], fmt, Path(folder), stem, title)
            media = SHAPE_FORMATS[fmt][1]
        return path.read_bytes(), path.name, media


def _surface_file(basis: SculptBasis, net: NDArray[np.float64], fmt: str, folder: Path,
                  stem: str, title: str) -> Path:
    from ..cad import patch_from_surface, write_3dm
    from ..export.frames import tessellate_frames
    from ..export.mesh import write_obj
    from ..export.nets import write_control_nets

    surface = basis.model.surface
    path = folder / f"{stem}{SHAPE_FORMATS[fmt][0]}"
    if fmt == "3dm":
        write_3dm(path, [patch_from_surface(surface, net)], names=[title], units=basis.units)
    elif fmt == "obj":
        # a trimmed surface: the grid clipped to its trims, as the page draws it
        vertices, faces = tessellate_frames(surface, net, basis.grid[0])
        write_obj(path, vertices, faces)
    else:
        write_control_nets(folder, stem, surface, [0.0], net[None], formats=("json",))
    return path


def _body_file(basis: SculptBasis, nets: list[NDArray[np.float64]], fmt: str, folder: Path,
               stem: str, title: str) -> Path:
    import zipfile

    from ..export.body import write_body_3dm, write_body_mesh
    from ..export.nets import write_control_nets

    patches = basis.patches
    faces = list(getattr(basis.model.body, "faces", range(len(patches))))
    path = folder / f"{stem}{SHAPE_FORMATS[fmt][0]}"
    if fmt == "3dm":
        write_body_3dm(path, patches, nets, [f"{title} face {f}" for f in faces], basis.units,
                       body=basis.model.body, name=title)
    elif fmt == "obj":
        write_body_mesh(path, patches, nets, None, basis.grid[0])
    else:
        path = folder / f"{stem}.zip"
        with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as bundle:
            for face, surface, net in zip(faces, patches, nets):
                name = f"{stem}-face-{face}"
                written, = write_control_nets(folder, name, surface, [0.0], net[None],
                                              formats=("json",))
                bundle.write(written, written.name)
    return path
