"""Control nets of a body's every face in every frame, as one JSON and one NPZ file.

* ``stem.json``: ``{"format": "splinedeform-body-control-nets", "version": 1, "faces":
  [k, …], "times": [...], "nets": {"k": document, …}}``, where each ``document`` is the
  face's own control-net document (:func:`.nets.control_net_document`: name, bases with
  their knots, weights, the times and the nets ``(F, n_u, n_v, 3)``, the convention that
  evaluates them) and ``reversed`` (whether the face's Brep marks it reversed: its outward
  normal is ``-(x_u × x_v)``), keyed by the face's number in the file;
* ``stem.npz``: ``format``, ``version``, ``faces`` ``(P,)`` and ``times`` ``(F,)``, and per
  face ``k`` the arrays of its single-net ``.npz`` named ``face<k>/<field>``
  (``face3/control_points``, ``face3/knots_u``, …, ``face3/reversed``).

:func:`read_body_control_nets` reads either back as ``{face: Surface}`` at one frame.
"""

from __future__ import annotations

import json
import os
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from ..errors import InputError
from ..input_files import load_json
from ..surface import Surface
from .atomic import _check_stem, _require_folder, write_text, write_with
from .nets import (CONTROL_NET_FORMATS, _npz_arrays, control_net_document, json_fields,
                   load_npz_arrays, npz_fields, surface_of)

BODY_NETS_FORMAT = "splinedeform-body-control-nets"
BODY_NETS_VERSION = 1


def body_nets_document(surfaces: Sequence[Surface], faces: Sequence[int], times: ArrayLike,
                       nets: Sequence[ArrayLike], orientation: Sequence[int] = ()
                       ) -> dict[str, Any]:
    """The content of a body's control-net file as JSON types (see the module docstring);
    ``orientation`` has ``-1`` per reversed patch (empty: none is)."""
    from .body import _signs

    if not (len(surfaces) == len(faces) == len(nets)) or not surfaces:
        raise InputError(f"a body's control nets need one face number and one set of nets "
                         f"per patch: got {len(surfaces)} patch(es), {len(faces)} face "
                         f"number(s) and {len(nets)} set(s) of nets")
    signs = _signs(orientation, len(surfaces))
    documents = {str(int(f)): {**control_net_document(s, times, n), "reversed": sign < 0}
                 for s, f, n, sign in zip(surfaces, faces, nets, signs)}
    return {"format": BODY_NETS_FORMAT, "version": BODY_NETS_VERSION,
            "faces": [int(f) for f in faces],
            "times": next(iter(documents.values()))["times"], "nets": documents}


def write_body_control_nets(directory: str | os.PathLike[str], stem: str,
                            surfaces: Sequence[Surface], faces: Sequence[int],
                            times: ArrayLike, nets: Sequence[ArrayLike],
                            formats: Sequence[str] = CONTROL_NET_FORMATS,
                            orientation: Sequence[int] = ()) -> list[Path]:
    """Write every face's nets at every frame as ``stem.json`` and/or ``stem.npz``, each
    face marked ``reversed`` where ``orientation`` has ``-1``."""
    folder = _require_folder(directory)
    _check_stem(stem)
    if not formats or any(f not in CONTROL_NET_FORMATS for f in formats):
        raise InputError(f"control nets are written as {CONTROL_NET_FORMATS}, got {list(formats)}")
    document = body_nets_document(surfaces, faces, times, nets, orientation)
    paths = []
    if "json" in formats:
        paths.append(write_text(folder / f"{stem}.json", json.dumps(document) + "\n"))
    if "npz" in formats:
        arrays = {"format": np.asarray(BODY_NETS_FORMAT), "version":
                  np.asarray(BODY_NETS_VERSION), "faces": np.asarray(document["faces"]),
                  "times": np.asarray(document["times"], dtype=float)}
        for key, face in document["nets"].items():
            own = _npz_arrays(face)
            own["control_points"] = np.asarray(face["control_points"], dtype=float)
            arrays.update({f"face{key}/{name}": value for name, value in own.items()})

        def save(tmp: Path) -> None:
            with open(tmp, "wb") as fh:
                np.savez(fh, **arrays)

        paths.append(write_with(folder / f"{stem}.npz", save))
    return paths


def read_body_control_nets(path: str | os.PathLike[str], frame: int = -1
                           ) -> dict[int, Surface]:
    """Every face of a file of :func:`write_body_control_nets` at ``frame`` (negative: from
    the end), ``{face number: Surface}``."""
    source = Path(path)
    suffix = source.suffix.lower()
    if suffix not in (".json", ".npz"):
        raise InputError(f"a body's control nets are read from .json or .npz files, got "
                         f"{source.name!r}")
    if not source.exists():
        raise InputError(f"control-net file {source} does not exist")
    if suffix == ".json":
        doc = load_json(source, "JSON body control-net file")
        _check_header(source, doc)
        nets = doc.get("nets")
        if not isinstance(nets, dict):
            raise InputError(f"{source}: 'nets' must map each face number to its control "
                             "net document")
        return {int(k): surface_of(json_fields(v, source), source, frame)
                for k, v in nets.items()}
    data = load_npz_arrays(source)
    _check_header(source, {k: data[k].item() for k in ("format", "version") if k in data})
    faces = [int(f) for f in np.atleast_1d(data.get("faces", np.zeros(0)))]
    out = {}
    for f in faces:
        prefix = f"face{f}/"
        own = {k[len(prefix):]: v for k, v in data.items() if k.startswith(prefix)}
        out[f] = surface_of(npz_fields(own, source), source, frame)
    return out


def _check_header(path: Path, doc: Any) -> None:
    if not isinstance(doc, dict) or doc.get("format") != BODY_NETS_FORMAT:
        raise InputError(f"{path}: not a body's control-net file (format "
                         f"{BODY_NETS_FORMAT!r}); a single net is read by read_control_net")
    if int(doc.get("version", 0)) > BODY_NETS_VERSION:
        raise InputError(f"{path}: body control-net file version {doc['version']} is newer "
                         f"than this splinedeform reads ({BODY_NETS_VERSION}); update "
                         "splinedeform")
