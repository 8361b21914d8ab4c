"""Files for other programs: meshes, ParaView time series, control nets and reports.

Every file is written atomically: the content goes to a temporary file in the target
folder, which then replaces the target with :func:`os.replace`. A failure part-way
leaves the previous target (or none) and no temporary file behind.

Meshes of a control net ``P`` are the surface sampled on a ``r × r`` parameter grid,
``X[i, j] = Σ_kl p_kl b_k(u_i) b_l(v_j)``, i.e. ``X = B_u P B_vᵀ`` per coordinate; for a
whole motion the collocation matrices ``B_u``, ``B_v`` are built once
(:func:`tessellate_frames`). Displacements are taken relative to a rest net:
``d = B_u (P - P_rest) B_vᵀ``.

meshio is imported lazily (it is part of the ``tool`` extra).
"""

from __future__ import annotations

import html
import json
import math
import os
import uuid
from collections.abc import Callable, Iterator, Mapping, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import Any
from xml.sax.saxutils import quoteattr

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .basis import BSplineBasis
from .errors import InputError
from .surface import Surface, grid_faces

MESH_FORMATS: tuple[str, ...] = (".obj", ".stl", ".ply", ".vtu", ".vtk")
CONTROL_NET_FORMAT = "splinedeform-control-nets"
CONTROL_NET_VERSION = 1
REPORT_TABLE_ROWS = 41
_MESHIO_OPTIONS: dict[str, dict[str, Any]] = {
    ".stl": {"binary": True}, ".ply": {"binary": True}, ".vtk": {"binary": True},
    ".vtu": {"binary": True, "compression": None}}


# -- atomic writing --------------------------------------------------------------
@contextmanager
def atomic_path(path: str | os.PathLike[str]) -> Iterator[Path]:
    """Yield a temporary path beside ``path`` (same suffix); on success it replaces ``path``.

    The temporary file (a fresh hidden name, created by the caller's writer, so it gets
    the usual permissions) lives in the target folder so :func:`os.replace` is an atomic
    rename. If the body raises, the temporary file is removed and ``path`` is untouched.
    """
    target = Path(path)
    if not target.parent.is_dir():
        raise InputError(f"cannot write {target}: folder {target.parent} does not exist")
    tmp = target.parent / f".{target.stem}.{uuid.uuid4().hex[:12]}.tmp{target.suffix}"
    try:
        yield tmp
        os.replace(tmp, target)
    finally:
        if tmp.exists():
            tmp.unlink()


def write_text(path: str | os.PathLike[str], text: str) -> Path:
    """Write ``text`` (UTF-8) to ``path`` atomically."""
    with atomic_path(path) as tmp:
        tmp.write_text(text, encoding="utf-8")
    return Path(path)


def write_with(path: str | os.PathLike[str], writer: Callable[[Path], object]) -> Path:
    """Call ``writer(tmp)`` on a temporary path and move the result to ``path`` atomically."""
    with atomic_path(path) as tmp:
        writer(tmp)
    return Path(path)


def _require_folder(directory: str | os.PathLike[str]) -> Path:
    folder = Path(directory)
    if not folder.is_dir():
        raise InputError(f"output folder {folder} does not exist (create it first)")
    return folder


def _check_stem(stem: str) -> str:
    if not isinstance(stem, str) or not stem or any(c in stem for c in "/\\\0"):
        raise InputError(f"file stem must be a non-empty name without path separators, "
                         f"got {stem!r}")
    return stem


# -- validation of frames ----------------------------------------------------------
def check_net(surface: Surface, net: ArrayLike, what: str = "control net") -> NDArray[np.float64]:
    """``net`` as a finite float array of shape ``(n_u, n_v, 3)`` matching ``surface``."""
    expected = (*surface.shape, 3)
    try:
        P = np.asarray(net, dtype=float)
    except (TypeError, ValueError) as exc:
        raise InputError(f"{what} must be a numeric array of shape {expected}: {exc}") from None
    if P.shape != expected:
        raise InputError(f"{what} must have shape {expected} (n_u, n_v, 3), got {P.shape}")
    if not np.all(np.isfinite(P)):
        raise InputError(f"{what} contains non-finite values")
    return P


def check_frames(surface: Surface, times: ArrayLike, nets: ArrayLike
                 ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Validate a motion: ``times (F,)`` finite and non-decreasing, ``nets (F, n_u, n_v, 3)``."""
    if not isinstance(surface, Surface):
        raise InputError(f"surface must be a splinedeform.Surface, got {type(surface).__name__}")
    try:
        t = np.asarray(times, dtype=float)
        P = np.asarray(nets, dtype=float)
    except (TypeError, ValueError) as exc:
        raise InputError(f"times and nets must be numeric arrays: {exc}") from None
    if t.ndim != 1 or t.size == 0:
        raise InputError(f"times must be a non-empty 1-D array (F,), got shape {t.shape}")
    if not np.all(np.isfinite(t)) or np.any(np.diff(t) < 0):
        raise InputError("times must be finite and non-decreasing")
    expected = (t.size, *surface.shape, 3)
    if P.shape != expected:
        raise InputError(f"nets must have shape {expected} (F, n_u, n_v, 3) for {t.size} "
                         f"time(s), got {P.shape}")
    if not np.all(np.isfinite(P)):
        raise InputError("nets contain non-finite values")
    return t, P


# -- tessellation of many frames ---------------------------------------------------------
def tessellate_frames(surface: Surface, nets: ArrayLike, resolution: int = 32
                      ) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    """Meshes of many control nets on one parameter grid, without re-assembly per frame.

    ``X_f = B_u P_f B_vᵀ`` per coordinate with ``(B_u)_ik = b_k(u_i)``, ``(B_v)_jl = b_l(v_j)``
    built once. ``nets`` has shape ``(..., n_u, n_v, 3)``; returns vertices
    ``(..., r_u r_v, 3)`` (row-major grid, as :meth:`Surface.tessellate`) and faces.
    """
    if isinstance(resolution, bool) or not isinstance(resolution, (int, np.integer)):
        raise InputError(f"resolution must be an integer >= 2, got {resolution!r}")
    u, v = surface.sample_parameters(int(resolution))
    Bu = surface.basis_u.matrix(u).toarray()
    Bv = surface.basis_v.matrix(v).toarray()
    P = np.asarray(nets, dtype=float)
    if P.shape[-3:] != (*surface.shape, 3):
        raise InputError(f"control nets must end in shape {(*surface.shape, 3)}, got {P.shape}")
    X = np.einsum("ik,...klc,jl->...ijc", Bu, P, Bv, optimize=True)
    return X.reshape(*P.shape[:-3], u.size * v.size, 3), grid_faces(u.size, v.size)


# -- meshes --------------------------------------------------------------------------
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
        ``name_0, name_1, ...``); OBJ and STL cannot hold it and drop it. STL stores
        float32 coordinates.
    """
    import meshio

    target = Path(path)
    suffix = target.suffix.lower()
    if suffix not in MESH_FORMATS:
        raise InputError(f"mesh format is chosen by the file suffix, one of {MESH_FORMATS}; "
                         f"got {target.name!r}")
    V, Fc = _check_mesh(vertices, faces)
    data = _check_point_data(point_data, V.shape[0])
    if suffix in (".obj", ".stl"):
        data = {}
    elif suffix == ".ply":
        data = _ply_point_data(data)
    cells = Fc.astype(np.int32) if suffix == ".ply" and V.shape[0] < 2**31 else Fc
    mesh = meshio.Mesh(V, [("triangle", cells)], point_data=data)
    options = _MESHIO_OPTIONS.get(suffix, {})
    return write_with(target, lambda tmp: meshio.write(tmp, mesh, file_format=suffix[1:],
                                                       **options))


# -- ParaView time series ------------------------------------------------------------
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


# -- control nets ----------------------------------------------------------------------
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


# -- reports -------------------------------------------------------------------------
def plain(value: Any) -> Any:
    """``value`` with numpy scalars/arrays, paths and tuples turned into JSON types.

    Non-finite floats become the strings ``"inf"``, ``"-inf"`` and ``"nan"`` (JSON has
    no such numbers).
    """
    if isinstance(value, Mapping):
        return {str(k): plain(v) for k, v in value.items()}
    if isinstance(value, np.ndarray):
        return plain(value.tolist())
    if isinstance(value, (list, tuple, set, frozenset)):
        return [plain(v) for v in value]
    if isinstance(value, np.generic):
        return plain(value.item())
    if isinstance(value, float):
        return value if math.isfinite(value) else str(value)
    if isinstance(value, complex):
        return {"real": plain(value.real), "imag": plain(value.imag)}
    if isinstance(value, (str, int, bool)) or value is None:
        return value
    if isinstance(value, os.PathLike):
        return os.fspath(value)
    raise InputError(f"report values must be numbers, strings, lists, mappings, arrays or "
                     f"paths; got {type(value).__name__}")


def format_value(value: Any) -> str:
    """A cell of report.md: floats with 6 significant digits (``{:.6g}``), lists joined."""
    if isinstance(value, bool) or value is None:
        return str(value)
    if isinstance(value, float):
        return f"{value:.6g}"
    if isinstance(value, list):
        return "[" + ", ".join(format_value(v) for v in value) + "]"
    if isinstance(value, dict):
        return ", ".join(f"{k}={format_value(v)}" for k, v in value.items())
    return str(value).replace("|", "\\|").replace("\n", " ")


def _is_scalar(value: Any) -> bool:
    return not isinstance(value, (dict, list))


def _table(header: Sequence[str], rows: Sequence[Sequence[Any]]) -> list[str]:
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    return lines + ["| " + " | ".join(format_value(c) for c in row) + " |" for row in rows]


def _thin(n: int) -> list[int]:
    """Row indices kept in a long table: evenly spaced, first and last included."""
    if n <= REPORT_TABLE_ROWS:
        return list(range(n))
    return sorted(set(np.linspace(0, n - 1, REPORT_TABLE_ROWS).round().astype(int).tolist()))


def _columns_table(section: dict[str, list[Any]]) -> list[str]:
    n = len(next(iter(section.values())))
    keep = _thin(n)
    lines = _table(list(section), [[section[k][i] for k in section] for i in keep])
    if len(keep) < n:
        lines.append(f"\n{len(keep)} of {n} rows shown; every row is in report.json.")
    return lines


def _flatten(section: dict[str, Any], prefix: str = "") -> list[tuple[str, Any]]:
    rows: list[tuple[str, Any]] = []
    for key, value in section.items():
        if isinstance(value, dict) and value:
            rows += _flatten(value, f"{prefix}{key}.")
        else:
            rows.append((f"{prefix}{key}", value))
    return rows


def section_markdown(section: Any) -> list[str]:
    """Markdown for one report section.

    * equal-length lists of scalars under every key → one column per key (a time table,
      long ones thinned to about 40 rows);
    * a mapping of mappings with scalar values → one row per outer key, one column per
      inner key (e.g. probes);
    * any other mapping → a ``key | value`` table with nested keys joined by dots;
    * a list of mappings → one row per item; anything else → the value itself.
    """
    if isinstance(section, dict) and section:
        values = list(section.values())
        if all(isinstance(v, list) and v and all(map(_is_scalar, v)) for v in values) \
                and len({len(v) for v in values}) == 1:
            return _columns_table(section)
        if all(isinstance(v, dict) and v and all(map(_is_scalar, v.values())) for v in values):
            columns = list(dict.fromkeys(k for v in values for k in v))
            return _table(["", *columns], [[name, *(v.get(c, "") for c in columns)]
                                           for name, v in section.items()])
        return _table(["key", "value"], _flatten(section))
    if isinstance(section, list) and section and all(isinstance(v, dict) for v in section):
        columns = list(dict.fromkeys(k for v in section for k in v))
        return _table(columns, [[v.get(c, "") for c in columns] for v in section])
    return [format_value(section)]


def report_markdown(report: Mapping[str, Any], title: str = "splinedeform report") -> str:
    """report.md: a heading and a table (see :func:`section_markdown`) per top-level key."""
    doc = plain(report)
    lines = [f"# {html.escape(' '.join(str(title).split()))}", ""]
    for name, section in doc.items():
        lines += [f"## {name.replace('_', ' ').capitalize()}", "", *section_markdown(section), ""]
    return "\n".join(lines)


def write_report(directory: str | os.PathLike[str], report: Mapping[str, Any]
                 ) -> tuple[Path, Path]:
    """Write ``report.json`` (every value, numpy converted) and ``report.md`` (tables).

    Typical top-level sections: ``inputs``, ``solver``, ``timings``, ``energies``,
    ``probes``; any mapping of JSON-able values works (see :func:`section_markdown`).
    """
    folder = _require_folder(directory)
    if not isinstance(report, Mapping):
        raise InputError(f"report must be a mapping of section name to content, got "
                         f"{type(report).__name__}")
    doc = plain(report)
    json_path = write_text(folder / "report.json", json.dumps(doc, indent=2) + "\n")
    md_path = write_text(folder / "report.md", report_markdown(doc))
    return json_path, md_path
