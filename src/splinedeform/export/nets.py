"""Control nets of every frame as JSON and NPZ, and reading them back."""

from __future__ import annotations

import json
import os
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from ..basis import BSplineBasis
from ..errors import InputError
from ..surface import Surface
from .atomic import _check_stem, _require_folder, write_text, write_with
from .frames import check_frames

CONTROL_NET_FORMAT = "splinedeform-control-nets"
CONTROL_NET_VERSION = 1


def _basis_description(basis: BSplineBasis) -> dict[str, Any]:
    return {"degree": int(basis.degree), "cells": int(basis.cells),
            "length": float(basis.length), "kind": str(basis.kind)}


def write_control_nets(directory: str | os.PathLike[str], stem: str, surface: Surface,
                       times: ArrayLike, nets: ArrayLike) -> list[Path]:
    """Write every frame's control net as ``stem.json`` and ``stem.npz``.

    Both hold the times ``(F,)``, the nets ``(F, n_u, n_v, 3)`` and the basis of each
    direction (degree, cells, length, kind), enough to rebuild the surface with
    :func:`read_control_net`. JSON floats are written with ``repr`` so they read back
    bit for bit.
    """
    folder = _require_folder(directory)
    _check_stem(stem)
    t, P = check_frames(surface, times, nets)
    basis = {"u": _basis_description(surface.basis_u), "v": _basis_description(surface.basis_v)}
    document = {"format": CONTROL_NET_FORMAT, "version": CONTROL_NET_VERSION,
                "name": surface.name, "shape": list(surface.shape), "basis": basis,
                "times": t.tolist(), "control_points": P.tolist()}
    json_path = write_text(folder / f"{stem}.json", json.dumps(document, indent=None) + "\n")
    arrays: dict[str, Any] = {"format": np.array(CONTROL_NET_FORMAT),
                              "version": np.array(CONTROL_NET_VERSION),
                              "name": np.array(surface.name), "times": t, "control_points": P}
    for d, desc in basis.items():
        arrays.update({f"{key}_{d}": np.array(value) for key, value in desc.items()})

    def save(tmp: Path) -> None:
        with open(tmp, "wb") as fh:
            np.savez(fh, **arrays)

    npz_path = write_with(folder / f"{stem}.npz", save)
    return [json_path, npz_path]


def _load_json_nets(path: Path) -> dict[str, Any]:
    try:
        doc = json.loads(path.read_text(encoding="utf-8"))
    except (UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise InputError(f"{path}: not a valid JSON control-net file: {exc}") from None
    if not isinstance(doc, dict) or "control_points" not in doc or "basis" not in doc:
        raise InputError(f"{path}: a control-net file needs the keys 'control_points' and "
                         f"'basis' (with 'u' and 'v': degree, cells, length, kind)")
    basis = doc["basis"]
    if not isinstance(basis, dict) or not all(isinstance(basis.get(d), dict) for d in "uv"):
        raise InputError(f"{path}: 'basis' must map 'u' and 'v' to "
                         f"{{degree, cells, length, kind}}")
    return {"control_points": doc["control_points"], "u": basis["u"], "v": basis["v"],
            "name": doc.get("name", path.stem)}


def _load_npz_nets(path: Path) -> dict[str, Any]:
    try:
        with np.load(path, allow_pickle=False) as z:
            data = {key: z[key] for key in z.files}
    except (OSError, ValueError) as exc:
        raise InputError(f"{path}: not a valid .npz control-net file: {exc}") from None
    keys = ("degree", "cells", "length", "kind")
    missing = [f"{k}_{d}" for d in "uv" for k in keys if f"{k}_{d}" not in data]
    if "control_points" not in data or missing:
        raise InputError(f"{path}: a control-net .npz needs 'control_points' and "
                         f"{', '.join(missing) or 'the basis arrays'}")
    return {"control_points": data["control_points"],
            "u": {k: data[f"{k}_u"].item() for k in keys},
            "v": {k: data[f"{k}_v"].item() for k in keys},
            "name": str(data["name"]) if "name" in data else path.stem}


def _basis_from(desc: Mapping[str, Any], where: str) -> BSplineBasis:
    missing = [k for k in ("degree", "cells", "length", "kind") if k not in desc]
    if missing:
        raise InputError(f"{where} misses {', '.join(missing)}")
    degree, cells = desc["degree"], desc["cells"]
    if not all(isinstance(x, (int, np.integer)) and not isinstance(x, bool) for x in (degree, cells)):
        raise InputError(f"{where}: degree and cells must be integers, got {degree!r}, {cells!r}")
    try:
        length = float(desc["length"])
    except (TypeError, ValueError):
        raise InputError(f"{where}: length must be a number, got {desc['length']!r}") from None
    return BSplineBasis(int(degree), int(cells), length, str(desc["kind"]))  # type: ignore[arg-type]


def read_control_net(path: str | os.PathLike[str], frame: int = -1) -> Surface:
    """Read a control net written by :func:`write_control_nets` (``.json`` or ``.npz``).

    Parameters
    ----------
    path : path-like
        ``.json`` or ``.npz``. A JSON file may also hold a single net ``(n_u, n_v, 3)``.
    frame : int
        Which frame to take; negative counts from the end (default: the last).

    Returns
    -------
    Surface
        The net on the stored bases, named after the stored name.
    """
    source = Path(path)
    suffix = source.suffix.lower()
    if suffix not in (".json", ".npz"):
        raise InputError(f"control nets are read from .json or .npz files, got {source.name!r}")
    if not source.is_file():
        raise InputError(f"control-net file {source} does not exist")
    data = _load_json_nets(source) if suffix == ".json" else _load_npz_nets(source)
    basis_u = _basis_from(data["u"], f"{source}: basis.u")
    basis_v = _basis_from(data["v"], f"{source}: basis.v")
    try:
        P = np.asarray(data["control_points"], dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"{source}: control_points must be a numeric array") from None
    if P.ndim == 3:
        P = P[None]
    if P.ndim != 4 or P.shape[0] == 0:
        raise InputError(f"{source}: control_points must have shape (F, n_u, n_v, 3) or "
                         f"(n_u, n_v, 3), got {P.shape}")
    if isinstance(frame, bool) or not isinstance(frame, (int, np.integer)) \
            or not -P.shape[0] <= frame < P.shape[0]:
        raise InputError(f"frame must be an integer in [{-P.shape[0]}, {P.shape[0] - 1}] "
                         f"for {source.name} ({P.shape[0]} frame(s)), got {frame!r}")
    return Surface(P[frame], basis_u, basis_v, name=str(data["name"]))

