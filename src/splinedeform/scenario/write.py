"""Writing a scenario back as TOML, with every default filled in."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any, Iterable

from ..boundary import EDGES
from .keys import (STEP_METHODS, IVP_METHODS, LOAD_KIND_KEYS, MATERIAL_KEYS, OUTPUT_KEYS,
                   PROFILE_KEYS, TOP_KEYS)
from .schema import PLATE_KEYS, SHELL_KEYS
from .spec import LoadSpec, Scenario, SolveSpec


def _toml_value(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if math.isinf(value):
            return "inf" if value > 0 else "-inf"
        return repr(value)
    if isinstance(value, (str, Path)):   # JSON escapes are TOML escapes; TOML also bans DEL
        return json.dumps(str(value), ensure_ascii=False).replace("\x7f", "\\u007f")
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_toml_value(v) for v in value) + "]"
    if isinstance(value, dict):
        return "{ " + ", ".join(f"{k} = {_toml_value(v)}" for k, v in value.items()) + " }"
    raise TypeError(f"cannot write {type(value).__name__} as TOML")


def _toml_table(header: str, items: Iterable[tuple[str, Any]]) -> list[str]:
    return [header] + [f"{k} = {_toml_value(v)}" for k, v in items if v is not None] + [""]


def _solve_items(solve: SolveSpec) -> list[tuple[str, Any]]:
    items: list[tuple[str, Any]] = [("kind", solve.kind)]
    if solve.kind == "static":
        items += [("frames", solve.frames)]
    if solve.kind == "dynamic":
        items += [("method", solve.method), ("t_end", solve.t_end)]
        items += [("times", solve.times)] if solve.times is not None else [("frames", solve.frames)]
        items += [("modes", solve.modes)]
        if solve.method in IVP_METHODS:
            items += [("rtol", solve.rtol), ("atol", solve.atol)]
        if solve.method in STEP_METHODS:
            items += [("dt", solve.dt)]
        if solve.method == "analytic":
            items += [("function_samples", solve.function_samples)]
    elif solve.kind == "modes":
        items += [("modes", solve.modes), ("frames", solve.frames)]
    return items


def _load_items(load: LoadSpec) -> list[tuple[str, Any]]:
    keys = ("kind",) + LOAD_KIND_KEYS[load.kind] + ("profile",) + PROFILE_KEYS[load.profile]
    return [(k, getattr(load, k)) for k in keys] + [("face", load.face)]


def scenario_to_toml(scenario: Scenario) -> str:
    """The scenario as TOML with every default filled in: exactly what would run.

    Reading the text back with :func:`parse_scenario` gives an equal scenario.
    """
    s = scenario
    out = [f"{k} = {_toml_value(getattr(s, k))}" for k in TOP_KEYS if getattr(s, k)]
    out += [""] if out else []
    surface = s.surface
    items: list[tuple[str, Any]] = [("shape", surface.shape), *surface.parameters.items()]
    fitted = [("cells", surface.cells), ("degree", surface.degree), ("knots", surface.knots),
              ("method", surface.method)]
    if surface.shape == "file":
        given = s.raw.get("surface", {})
        grid = surface.path is not None and surface.path.suffix.lower() == ".npy"
        items += [("path", surface.path)]
        items += [item for item in fitted if grid or item[0] in given]
        items += [("frame", surface.frame)] if "frame" in given else []
    elif surface.shape == "cad":
        if "face" not in s.raw.get("surface", {}):       # every face (faces), not face 0
            items = [item for item in items if item[0] != "face"]
        items += [("path", surface.path)]
    else:
        items += fitted
    items += [(k, list(getattr(surface, k))) for k in ("refine", "elevate")
              if getattr(surface, k) != (0, 0)]
    if surface.trim is not None:
        items += [("trim", surface.trim.model_dump(exclude_none=True))]
    out += _toml_table("[surface]", items)
    skip = PLATE_KEYS if s.material.physics == "shell" else SHELL_KEYS
    out += _toml_table("[material]", [(k, getattr(s.material, k)) for k in MATERIAL_KEYS
                                      if k not in skip])
    boundary: list[tuple[str, Any]] = [(e, getattr(s.boundary, e)) for e in EDGES]
    region = {k: getattr(s.boundary, f"free_{k}") for k in "uv"
              if getattr(s.boundary, f"free_{k}") is not None}
    if region:
        boundary.append(("free_region", region))
    if s.boundary.free_points is not None:
        boundary.append(("free_points", [list(p) for p in s.boundary.free_points]))
    loops = s.raw.get("boundary", {}).get("loops")      # a CAD face's, read when built
    if loops:
        boundary.append(("loops", dict(loops)))
    faces = s.raw.get("boundary", {}).get("faces")      # a body's presets per edge
    if faces:
        boundary.append(("faces", dict(faces)))
    faces_free = s.raw.get("boundary", {}).get("faces_free_points")   # a body's moving points
    if faces_free:
        boundary.append(("faces_free_points",
                         {k: [list(p) for p in v] for k, v in faces_free.items()}))
    out += _toml_table("[boundary]", boundary)
    for load in s.loads:
        out += _toml_table("[[load]]", _load_items(load))
    out += _toml_table("[solve]", _solve_items(s.solve))
    out += _toml_table("[output]", [(k, getattr(s.output, k)) for k in OUTPUT_KEYS])
    return "\n".join(out).rstrip() + "\n"


