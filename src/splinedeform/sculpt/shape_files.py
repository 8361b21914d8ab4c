"""The sculpted shape as a file the page downloads: ``.3dm``, OBJ or a control-net JSON.

The shape is the control net of the page's modal state ``q`` (``3 k`` numbers, mode-major),
``P + T Φ_net q`` (:func:`.history.baked_net`, the net a bake would make the rest shape),
written by the project's own writers: :func:`splinedeform.cad.write_3dm` (a NURBS surface
on the model's knot vectors, weights 1 or ``a_i b_j``), :func:`splinedeform.export.mesh.
write_obj` (the surface sampled on the page's grid, vertex normals) and
:func:`splinedeform.export.nets.write_control_nets` (the project's net file, which
``shape = "file"`` reads back). Each is written to a private temporary folder and its
bytes returned; nothing is written beside the save.
"""

from __future__ import annotations

import re
import tempfile
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from .history import baked_net
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
    from ..cad import patch_from_surface, write_3dm
    from ..export.mesh import write_obj
    from ..export.nets import write_control_nets

    suffix, media = SHAPE_FORMATS[fmt]
    net = baked_net(basis, q)
    surface = basis.model.surface
    stem = file_stem(title) + "-shape"
    with tempfile.TemporaryDirectory(prefix="splinedeform-shape-") as folder:
        path = Path(folder) / f"{stem}{suffix}"
        if fmt == "3dm":
            write_3dm(path, [patch_from_surface(surface, net)], names=[title])
        elif fmt == "obj":
            res = (basis.samples_u.size, basis.samples_v.size)
            vertices, faces = surface.tessellate(res, control_points=net)
            write_obj(path, vertices, faces)
        else:
            write_control_nets(folder, stem, surface, [0.0], net[None], formats=("json",))
        return path.read_bytes(), path.name, media
