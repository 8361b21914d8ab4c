"""Control nets of every frame as JSON and NPZ, and reading them back."""

from __future__ import annotations

import json
import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..basis import KNOT_KINDS, BSplineBasis
from ..errors import InputError
from ..input_files import check_array_file, load_json, open_input
from ..knots import KnotVectorBasis, RationalBasis
from ..surface import Basis, Surface
from .atomic import _check_stem, _require_folder, write_text, write_with
from .frames import check_frames

CONTROL_NET_FORMAT = "splinedeform-control-nets"
CONTROL_NET_VERSION = 2
CONTROL_NET_FORMATS: tuple[str, ...] = ("json", "npz")
#: knot kinds stored with their full knot vector only (see :class:`KnotVectorBasis`)
GENERAL_KINDS: tuple[str, ...] = ("general", "rational")
#: stated in every file, so that a reader needs neither our source nor our docs
CONVENTION = (
    "x(u, v) = sum_i sum_j c[i][j] N_i(u) M_j(v) for u in basis.u.domain, v in basis.v.domain; "
    "N_i (M_j) is the B-spline of basis.u.degree (basis.v.degree) on the knots "
    "basis.u.knots[i : i + degree + 2] (Cox-de Boor, knots as given, not normalised), and "
    "c[i][j] = control_points[frame][basis.u.coefficient_index[i]]"
    "[basis.v.coefficient_index[j]]. For kind 'open' and 'uniform' coefficient_index is "
    "0, 1, ..., n - 1 (the control points in order). For kind 'periodic' the n = cells "
    "control points hold one period: the knots are uniform, extended by degree cells on "
    "each side of the domain, and coefficient_index = n - degree, ..., n - 1, 0, 1, ..., "
    "n - 1 (the last degree control points repeated in front), so that x has period "
    "length in that direction. Kind 'general' (any knot vector) and 'rational' have "
    "coefficient_index 0, ..., n - 1 too. weights[i][j] > 0 are the NURBS weights of "
    "control point [i][j] (the same for every frame; all 1 unless a direction is "
    "'rational'): with w[i][j] = weights[basis.u.coefficient_index[i]]"
    "[basis.v.coefficient_index[j]], x(u, v) = sum_ij w[i][j] c[i][j] N_i(u) M_j(v) / "
    "sum_ij w[i][j] N_i(u) M_j(v). In the .npz file the same fields are named "
    "<field>_u and <field>_v.")


def coefficient_index(basis: BSplineBasis) -> NDArray[np.int64]:
    """Control-point row of each coefficient on the full knot vector ``basis.knots``.

    ``basis.knots`` has ``N + n + 1`` knots for ``N`` coefficients. Open and uniform:
    ``N = m + n`` functions, the identity ``0, …, N - 1``. Periodic: function ``j`` of
    the basis is ``b^n(x/h - j)`` wrapped modulo ``L``, i.e. the B-spline on the knots
    ``t_{j+n} … t_{j+2n+1}`` of ``t_i = (i - n) h``; unwrapped, coefficient ``i`` of the
    ``m + n`` B-splines on those knots is control point ``(i - n) mod m``.
    """
    if basis.periodic:
        return np.mod(np.arange(basis.cells + basis.degree) - basis.degree, basis.cells)
    return np.arange(basis.size)


def _basis_description(basis: BSplineBasis) -> dict[str, Any]:
    """Everything a reader needs for one direction (see :data:`CONVENTION`)."""
    return {"degree": int(basis.degree), "cells": int(basis.cells),
            "length": float(basis.length), "kind": str(basis.kind),
            "periodic": bool(basis.periodic), "domain": [0.0, float(basis.length)],
            "knots": basis.knots.tolist(),
            "coefficient_index": coefficient_index(basis).tolist()}


def control_net_document(surface: Surface, times: ArrayLike, nets: ArrayLike
                         ) -> dict[str, Any]:
    """The content of a control-net file as JSON types (one mapping for both formats).

    Keys: ``format``, ``version``, ``convention`` (the text of :data:`CONVENTION`),
    ``name``, ``shape`` ``[n_u, n_v]``, ``domain`` ``[[0, L_u], [0, L_v]]``, ``basis``
    (``u`` and ``v``: degree, cells, length, kind, periodic, domain, knots,
    coefficient_index), ``times`` ``(F,)``, ``control_points`` ``(F, n_u, n_v, 3)`` and
    ``weights`` ``(n_u, n_v)`` (NURBS weights, constant in time; all 1 unless rational).
    """
    t, P = check_frames(surface, times, nets)
    basis = {"u": _basis_description(surface.basis_u), "v": _basis_description(surface.basis_v)}
    return {"format": CONTROL_NET_FORMAT, "version": CONTROL_NET_VERSION,
            "convention": CONVENTION, "name": surface.name, "shape": list(surface.shape),
            "domain": [list(d) for d in surface.domain], "basis": basis,
            "times": t.tolist(), "control_points": P.tolist(),
            "weights": surface.weights.tolist()}


def _npz_arrays(document: Mapping[str, Any]) -> dict[str, NDArray[Any]]:
    """The document as flat arrays: ``basis.u.knots`` becomes ``knots_u`` and so on."""
    arrays = {key: np.asarray(value) for key, value in document.items() if key != "basis"}
    for d, desc in document["basis"].items():
        arrays.update({f"{key}_{d}": np.asarray(value) for key, value in desc.items()})
    return arrays


def write_control_nets(directory: str | os.PathLike[str], stem: str, surface: Surface,
                       times: ArrayLike, nets: ArrayLike,
                       formats: Sequence[str] = CONTROL_NET_FORMATS) -> list[Path]:
    """Write every frame's control net as ``stem.json`` and/or ``stem.npz``.

    Both hold the times ``(F,)``, the nets ``(F, n_u, n_v, 3)``, the full knot vector,
    parameter domain and index convention of each direction (see
    :func:`control_net_document` and :data:`CONVENTION`): enough to rebuild the surface
    with any B-spline library, or with :func:`read_control_net`. JSON floats are written
    with ``repr`` so they read back bit for bit.

    Parameters
    ----------
    formats : sequence of {"json", "npz"}
        Which files to write (default both), in this order.
    """
    folder = _require_folder(directory)
    _check_stem(stem)
    unknown = [f for f in formats if f not in CONTROL_NET_FORMATS]
    if unknown or not formats:
        raise InputError(f"control nets are written as {CONTROL_NET_FORMATS}, got {list(formats)}")
    document = control_net_document(surface, times, nets)
    paths = []
    if "json" in formats:
        paths.append(write_text(folder / f"{stem}.json", json.dumps(document) + "\n"))
    if "npz" in formats:
        arrays = _npz_arrays(document)
        arrays["control_points"] = np.asarray(document["control_points"], dtype=float)

        def save(tmp: Path) -> None:
            with open(tmp, "wb") as fh:
                np.savez(fh, **arrays)

        paths.append(write_with(folder / f"{stem}.npz", save))
    return paths


_BASIS_KEYS = ("degree", "cells", "length", "kind")


def _check_header(path: Path, fmt: Any, version: Any) -> None:
    if fmt is not None and str(fmt) != CONTROL_NET_FORMAT:
        raise InputError(f"{path}: format is {str(fmt)!r}, not {CONTROL_NET_FORMAT!r}")
    if version is not None:
        try:
            number = int(version)
        except (TypeError, ValueError):
            raise InputError(f"{path}: version must be an integer, got {version!r}") from None
        if number > CONTROL_NET_VERSION:
            raise InputError(f"{path}: control-net file version {number} is newer than this "
                             f"splinedeform reads ({CONTROL_NET_VERSION}); update splinedeform")


def _load_json_nets(path: Path) -> dict[str, Any]:
    return json_fields(load_json(path, "JSON control-net file"), path)


def json_fields(doc: Any, path: Path) -> dict[str, Any]:
    """The fields of one control net's JSON document ``doc`` (read from ``path``), as
    :func:`read_control_net` takes them; refused where keys are missing."""
    if not isinstance(doc, dict) or "control_points" not in doc or "basis" not in doc:
        raise InputError(f"{path}: a control-net file needs the keys 'control_points' and "
                         f"'basis' (with 'u' and 'v': degree, cells, length, kind)")
    _check_header(path, doc.get("format"), doc.get("version"))
    basis = doc["basis"]
    if not isinstance(basis, dict) or not all(isinstance(basis.get(d), dict) for d in "uv"):
        raise InputError(f"{path}: 'basis' must map 'u' and 'v' to "
                         f"{{degree, cells, length, kind}}")
    return {"control_points": doc["control_points"], "u": basis["u"], "v": basis["v"],
            "name": doc.get("name", path.stem), "weights": doc.get("weights")}


def _load_npz_nets(path: Path) -> dict[str, Any]:
    return npz_fields(load_npz_arrays(path), path)


def load_npz_arrays(path: Path) -> dict[str, NDArray[Any]]:
    """Every array of a control-net ``.npz`` file (no pickles), refused where unreadable."""
    try:
        with open_input(path, "control-net file") as fh:
            check_array_file(fh, path)
            with np.load(fh, allow_pickle=False) as z:
                return {key: z[key] for key in z.files}
    except (OSError, ValueError, EOFError) as exc:
        raise InputError(f"{path}: not a valid .npz control-net file: {exc}") from None


def npz_fields(data: Mapping[str, Any], path: Path) -> dict[str, Any]:
    """The fields of one control net's ``.npz`` arrays ``data`` (read from ``path``), as
    :func:`read_control_net` takes them; refused where arrays are missing."""
    missing = [f"{k}_{d}" for d in "uv" for k in _BASIS_KEYS if f"{k}_{d}" not in data]
    if "control_points" not in data or missing:
        raise InputError(f"{path}: a control-net .npz needs 'control_points' and "
                         f"{', '.join(missing) or 'the basis arrays'}")
    _check_header(path, data["format"].item() if "format" in data else None,
                  data["version"].item() if "version" in data else None)

    def direction(d: str) -> dict[str, Any]:
        desc: dict[str, Any] = {}
        for key in (*_BASIS_KEYS, "knots"):
            if f"{key}_{d}" in data:
                value = data[f"{key}_{d}"]
                desc[key] = value if key == "knots" else \
                    (value.item() if value.ndim == 0 else value.tolist())
        return desc

    return {"control_points": data["control_points"], "u": direction("u"), "v": direction("v"),
            "name": str(data["name"]) if "name" in data else path.stem,
            "weights": data.get("weights")}


def real_array(value: Any, where: str) -> NDArray[np.float64]:
    """``value`` as a float array; strings, objects, booleans and complex numbers refused.

    ``np.asarray(["1.5"], dtype=float)`` would parse strings and ``complex`` would drop an
    imaginary part, so the stored dtype is checked first (integers are widened).
    """
    try:
        raw = np.asarray(value)
    except (TypeError, ValueError) as exc:     # ragged nested lists
        raise InputError(f"{where} must be a numeric array: {exc}") from None
    if raw.dtype.kind not in "iuf":
        what = _DTYPE_KINDS.get(raw.dtype.kind, "not numbers")
        raise InputError(f"{where} must be an array of real numbers, got dtype {raw.dtype} "
                         f"({what})")
    return raw.astype(float)


_DTYPE_KINDS = {"U": "strings", "S": "bytes", "O": "mixed or nested objects",
                "b": "booleans", "c": "complex numbers", "V": "records", "M": "dates"}


def _basis_from(desc: Mapping[str, Any], size: int, where: str) -> Basis:
    """The basis a file describes, checked against the net's size ``size`` and its knots."""
    missing = [k for k in _BASIS_KEYS if k not in desc]
    if missing:
        raise InputError(f"{where} misses {', '.join(missing)}")
    degree, cells, kind = desc["degree"], desc["cells"], desc["kind"]
    if not all(isinstance(x, (int, np.integer)) and not isinstance(x, bool) for x in (degree, cells)):
        raise InputError(f"{where}: degree and cells must be integers, got {degree!r}, {cells!r}")
    try:
        length = float(desc["length"])
    except (TypeError, ValueError):
        raise InputError(f"{where}: length must be a number, got {desc['length']!r}") from None
    if kind in GENERAL_KINDS:
        return _general_basis(desc, size, where)
    if kind not in KNOT_KINDS:
        raise InputError(f"{where}.kind must be one of {KNOT_KINDS + GENERAL_KINDS}, "
                         f"got {kind!r}")
    # check the size before building anything, so a hostile 'cells' allocates nothing
    expected = int(cells) if kind == "periodic" else int(cells) + int(degree)
    if expected != size:
        raise InputError(f"{where}: a {kind} basis of degree {degree} on {cells} cells has "
                         f"{expected} functions, but control_points has shape {size} in this "
                         f"direction")
    basis = BSplineBasis(int(degree), int(cells), length, kind)
    if "knots" in desc:
        _check_knots(desc["knots"], basis, where)
    return basis


def _general_basis(desc: Mapping[str, Any], size: int, where: str) -> KnotVectorBasis:
    """A 'general' or 'rational' direction: the polynomial basis of its stored knots."""
    if "knots" not in desc:
        raise InputError(f"{where}: a {desc['kind']} basis needs its knots")
    knots = real_array(desc["knots"], f"{where}.knots")
    try:
        basis = KnotVectorBasis(int(desc["degree"]), knots)
    except InputError as exc:
        raise InputError(f"{where}: {exc}") from None
    if basis.size != size:
        raise InputError(f"{where}: its knots give {basis.size} functions, but control_points "
                         f"has shape {size} in this direction")
    return basis


def _with_weights(basis_u: Basis, basis_v: Basis, kinds: tuple[Any, Any], weights: Any,
                  source: Path) -> tuple[Basis, Basis, NDArray[np.float64] | None]:
    """Rational directions take their factor of the stored weights ``w = a bᵀ``; weights
    that differ on polynomial directions are general weights (the third item)."""
    if weights is None:
        if "rational" in kinds:
            raise InputError(f"{source}: a rational net needs weights, the file has none")
        return basis_u, basis_v, None
    w = real_array(weights, f"{source}: weights")
    if w.shape != (basis_u.size, basis_v.size) or not np.all(np.isfinite(w)) or np.any(w <= 0):
        raise InputError(f"{source}: NURBS weights must be > 0 of shape "
                         f"{(basis_u.size, basis_v.size)}, got shape {w.shape}")
    if "rational" not in kinds:
        return basis_u, basis_v, (None if np.ptp(w) == 0 else w)
    from ..cad import weight_factors

    factors = weight_factors(w)
    if factors is None:
        raise InputError(f"{source}: its weights are not a product w_ij = a_i b_j, but "
                         "its directions say 'rational' (weights per direction)")
    a, b = factors
    return (RationalBasis(basis_u, a) if kinds[0] == "rational" else basis_u,
            RationalBasis(basis_v, b) if kinds[1] == "rational" else basis_v, None)


def _check_knots(knots: Any, basis: BSplineBasis, where: str) -> None:
    """Stored knots must be those of the layout, to ``1e-12 L`` (they are written by repr)."""
    try:
        t = np.asarray(knots, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"{where}.knots must be a list of numbers") from None
    if t.shape != basis.knots.shape or not np.all(np.abs(t - basis.knots)
                                                  <= 1e-12 * basis.length):
        raise InputError(f"{where}.knots are not the {basis.kind} knots of degree "
                         f"{basis.degree} on {basis.cells} cells of [0, {basis.length:g}] "
                         f"({basis.knots.size} values); this reader takes the open, uniform "
                         f"and periodic layouts only")


def read_control_net(path: str | os.PathLike[str], frame: int = -1) -> Surface:
    """Read a control net written by :func:`write_control_nets` (``.json`` or ``.npz``).

    Parameters
    ----------
    path : path-like
        ``.json`` or ``.npz``. A JSON file may also hold a single net ``(n_u, n_v, 3)``.
        Files of version 1 (without knots) are read too.
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
    if not source.exists():        # a pipe or device is refused on opening, naming it
        raise InputError(f"control-net file {source} does not exist")
    data = _load_json_nets(source) if suffix == ".json" else _load_npz_nets(source)
    return surface_of(data, source, frame)


def surface_of(data: Mapping[str, Any], source: Path, frame: int = -1) -> Surface:
    """The surface of one control net's fields ``data`` (:func:`read_control_net`) at
    ``frame``; ``source`` names the file in errors."""
    P = real_array(data["control_points"], f"{source}: control_points")
    if P.ndim == 3:
        P = P[None]
    if P.ndim != 4 or P.shape[0] == 0 or P.shape[-1] != 3:
        raise InputError(f"{source}: control_points must have shape (F, n_u, n_v, 3) or "
                         f"(n_u, n_v, 3), got {P.shape}")
    basis_u = _basis_from(data["u"], P.shape[1], f"{source}: basis.u")
    basis_v = _basis_from(data["v"], P.shape[2], f"{source}: basis.v")
    basis_u, basis_v, net_weights = _with_weights(
        basis_u, basis_v, (data["u"]["kind"], data["v"]["kind"]), data.get("weights"), source)
    if isinstance(frame, bool) or not isinstance(frame, (int, np.integer)) \
            or not -P.shape[0] <= frame < P.shape[0]:
        raise InputError(f"frame must be an integer in [{-P.shape[0]}, {P.shape[0] - 1}] "
                         f"for {source.name} ({P.shape[0]} frame(s)), got {frame!r}")
    return Surface(P[frame], basis_u, basis_v, name=str(data["name"]), net_weights=net_weights)
