"""Validating a scenario: the checks of every key, then the cross-field rules of the physics."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any, Iterable, Mapping

from ..boundary import EDGES
from .checks import Key, _Invalid
from .geometry import length_problems
from .paths import inside as _inside
from .keys import (BOUNDARY_KEYS, FORMAT_ALIASES, FREE_REGION_KEYS, LOAD_KEYS, LOAD_KIND_KEYS,
                   METHOD_SETTINGS, MATERIAL_KEYS, PROFILE_KEYS, SHAPE_PARAMETERS, SOLVE_KEYS,
                   SOLVE_KIND_KEYS, SURFACE_KEYS, TABLES, TOP_KEYS, OUTPUT_KEYS)
from .locate import _describe, _Problems
from .schema import PLATE_KEYS, SHELL_EDGES, SHELL_KEYS
from .spec import (BoundarySpec, LoadSpec, MaterialSpec, OutputSpec, Scenario, SolveSpec,
                   SurfaceSpec)


# -- validation ------------------------------------------------------------------------
def _check_table(raw: Any, schema: Mapping[str, Key], path: str, problems: _Problems,
                 table_name: str, allowed_extra: Mapping[str, Key] | None = None
                 ) -> dict[str, Any]:
    """Check each key of a table against its schema; return the valid values given."""
    if not isinstance(raw, dict):
        problems.add(path, f"expected a table [{table_name}], got {_describe(raw)}")
        return {}
    known = {**schema, **(allowed_extra or {})}
    values: dict[str, Any] = {}
    for key, value in raw.items():
        where = f"{path}.{key}"
        if key not in known:
            problems.add(where, f"unknown key in [{table_name}]; allowed keys: "
                                f"{', '.join(known)}")
            continue
        try:
            values[key] = known[key].check(value)
        except _Invalid as exc:
            problems.add(where + exc.sub, str(exc))
    return values


def top_level(raw: Mapping[str, Any], top_keys: Mapping[str, Key], tables: Iterable[str],
              table_names: Iterable[str], problems: _Problems) -> dict[str, Any]:
    """The checked values of a file's top-level keys; an unknown key or table, or a bad
    value, is added to ``problems`` at its key (``table_names`` as the message lists them)."""
    tables = set(tables)
    for key in raw:
        if key not in tables and key not in top_keys:
            problems.add(key, "unknown key or table; allowed: "
                              f"{', '.join([*top_keys, *table_names])}")
    top: dict[str, Any] = {}
    for key in top_keys:
        if key in raw:
            try:
                top[key] = top_keys[key].check(raw[key])
            except _Invalid as exc:
                problems.add(key, str(exc))
    return top


def _require(values: Mapping[str, Any], raw: Any, keys: Iterable[str], schema: Mapping[str, Key],
             path: str, problems: _Problems, reason: str = "") -> None:
    """Report each key of ``keys`` missing from the table ``raw``."""
    if not isinstance(raw, dict):
        return
    for key in keys:
        if key not in raw:
            problems.add(f"{path}.{key}", f"missing{reason}; expected {schema[key].allowed}")


def _not_applicable(raw: Any, keys: Iterable[str], allowed: Iterable[str], path: str,
                    problems: _Problems, context: str) -> None:
    """Report keys given although they do not apply (``context`` says why)."""
    if not isinstance(raw, dict):
        return
    allowed = set(allowed)
    for key in keys:
        if key in raw and key not in allowed:
            problems.add(f"{path}.{key}", f"does not apply {context}")


def _with_defaults(schema: Mapping[str, Key], values: Mapping[str, Any],
                   keys: Iterable[str]) -> dict[str, Any]:
    out = {}
    for key in keys:
        if key in values:
            out[key] = values[key]
        elif not schema[key].required:
            out[key] = schema[key].default
    return out


def _validate(raw: dict[str, Any], source: str, lines: Mapping[str, int],
              origins: Mapping[str, str], directory: Path,
              allow_outside_paths: bool = False) -> Scenario:
    problems = _Problems(source, lines, origins)
    top = top_level(raw, TOP_KEYS, TABLES, [f"[{t}]" for t in TABLES], problems)
    surface = _validate_surface(raw, problems, directory, allow_outside_paths)
    material = _validate_material(raw, problems, surface)
    if surface is not None and material is not None:
        for key, message in length_problems(surface, material):
            problems.add(key, message)
    physics = material.physics if material is not None else "parametric"
    boundary = _validate_boundary(raw, problems, physics)
    solve = _validate_solve(raw, problems, physics)
    loads = _validate_loads(raw, problems, solve)
    output = _validate_output(raw, problems, solve)
    problems.raise_if_any()
    assert surface and material and boundary and solve and output is not None
    return Scenario(surface=surface, material=material, boundary=boundary, loads=loads,
                    solve=solve, output=output, title=top.get("title", ""),
                    description=top.get("description", ""), source=source,
                    directory=directory, raw=raw, lines=dict(lines), origins=dict(origins),
                    allow_outside_paths=allow_outside_paths)


def _validate_surface(raw: Mapping[str, Any], problems: _Problems,
                      directory: Path, allow_outside_paths: bool = False) -> SurfaceSpec | None:
    if "surface" not in raw:
        problems.add("surface", "missing table [surface]; it needs at least shape = "
                                f"{SURFACE_KEYS['shape'].allowed}")
        return None
    table = raw["surface"]
    parameters = {k: v for params in SHAPE_PARAMETERS.values() for k, v in params.items()}
    values = _check_table(table, SURFACE_KEYS, "surface", problems, "surface", parameters)
    _require(values, table, ["shape"], SURFACE_KEYS, "surface", problems)
    shape = values.get("shape")
    if shape is None:
        return None
    own = SHAPE_PARAMETERS[shape]
    for key in parameters:
        if isinstance(table, dict) and key in table and key not in own:
            problems.add(f"surface.{key}", f"is not a parameter of shape {shape!r}; its "
                                           f"parameters are: {', '.join(own) or 'none'}")
    if shape == "file":
        _require(values, table, ["path"], SURFACE_KEYS, "surface", problems,
                 " (shape = \"file\" reads the net or grid from this file)")
    elif shape == "cad":
        _require(values, table, ["path"], SURFACE_KEYS, "surface", problems,
                 " (shape = \"cad\" reads a NURBS surface from this file)")
        _not_applicable(table, ["frame", "cells", "degree", "knots", "method"], [], "surface",
                        problems, "to shape \"cad\" (the file holds the surface's own "
                                  "degrees, knots and weights)")
        _not_applicable(table, ["trim"], [], "surface", problems,
                        "to shape \"cad\" (a CAD face's trim comes from its file)")
    else:
        _not_applicable(table, ["path", "frame"], [], "surface", problems,
                        f"to shape {shape!r}, only to shape = \"file\" (path also to \"cad\")")
    spec = _with_defaults(SURFACE_KEYS, values, [k for k in SURFACE_KEYS if k != "shape"])
    if spec.get("path") is not None:
        spec["path"] = _inside(directory, spec["path"], allow_outside_paths, problems)
    params = {k: values.get(k, key.default) for k, key in own.items()}
    return SurfaceSpec(shape=shape, parameters=params, **spec)


def _validate_material(raw: Mapping[str, Any], problems: _Problems,
                       surface: SurfaceSpec | None) -> MaterialSpec | None:
    table = raw.get("material", {})
    values = _check_table(table, MATERIAL_KEYS, "material", problems, "material")
    if values.get("physics") == "shell":
        return _validate_shell_material(table, values, problems, surface)
    spec = MaterialSpec(**values)
    _not_applicable(table, SHELL_KEYS, (), "material", problems,
                    f"to physics {spec.physics!r}, only to \"shell\" (the thin plate under "
                    "tension takes mass and the weights w10 ... w02)")
    weights = ("w10", "w01", "w20", "w11", "w02")
    if isinstance(table, dict) and all(getattr(spec, w) == 0 for w in weights) and not any(
            w in table and w not in values for w in weights):
        problems.add("material", "all stiffness weights are zero (or missing): the surface "
                                 "would have no elastic energy; set a tension weight (w10, "
                                 "w01) or a bending weight (w20, w11, w02) > 0")
    bending = spec.w20 > 0 or spec.w11 > 0 or spec.w02 > 0
    if (bending and surface is not None and surface.shape not in ("file", "cad")
            and surface.degree < 2):
        problems.add("surface.degree", "bending weights (w20, w11, w02) need second "
                                       "derivatives: degree must be >= 2")
    return spec


def _validate_shell_material(table: Any, values: dict[str, Any], problems: _Problems,
                             surface: SurfaceSpec | None) -> MaterialSpec:
    """``physics = "shell"``: E, nu, thickness required, the plate's keys refused."""
    _not_applicable(table, PLATE_KEYS, (), "material", problems,
                    "to physics \"shell\" (a Kirchhoff–Love shell takes E, nu, thickness and "
                    "density; the thin-plate weights and mass do not apply)")
    _require(values, table, ("E", "nu", "thickness"), MATERIAL_KEYS, "material", problems,
             " (physics \"shell\" needs it)")
    values.setdefault("density", 1.0)
    if surface is not None and surface.shape not in ("file", "cad") and surface.degree < 2:
        problems.add("surface.degree", "the Kirchhoff–Love shell (physics \"shell\") needs "
                                       "curvatures, so second derivatives: degree must be >= 2")
    return MaterialSpec(**{k: v for k, v in values.items() if k not in PLATE_KEYS})


def _validate_boundary(raw: Mapping[str, Any], problems: _Problems,
                       physics: str = "parametric") -> BoundarySpec | None:
    table = raw.get("boundary", {})
    values = _check_table(table, BOUNDARY_KEYS, "boundary", problems, "boundary")
    for edge in EDGES:
        kind = values.get(edge)
        if kind in SHELL_EDGES and physics != "shell":
            problems.add(f"boundary.{edge}", f"{kind!r} is an edge of the Kirchhoff–Love shell "
                                             f"only (material.physics = \"shell\"), not of "
                                             f"physics {physics!r}")
    values.pop("faces", None)           # a body's, read by scenario.body.face_presets
    faces_free = values.pop("faces_free_points", None)      # a body's: scenario.body.face_masks
    for face, listed in (faces_free or {}).items():
        if not listed:
            problems.add(f"boundary.faces_free_points.{face}", "is empty; list at least one "
                         "[i, j] or leave the face out (then all its control points move)")
    values.pop("loops", None)           # a CAD face's, read by scenario.cad_trim.face_loop_presets
    region = values.pop("free_region", None)
    box: dict[str, tuple[float, float] | None] = {"free_u": None, "free_v": None}
    if region is not None:
        ranges = _check_table(region, FREE_REGION_KEYS, "boundary.free_region", problems,
                              "boundary.free_region")
        if isinstance(region, dict) and not region:
            problems.add("boundary.free_region", "is empty; give u = [low, high] and/or "
                                                 "v = [low, high]")
        for key, (low, high) in ranges.items():
            if not low < high:
                problems.add(f"boundary.free_region.{key}",
                             f"expected [low, high] with low < high, got [{low:g}, {high:g}]")
            box[f"free_{key}"] = (low, high)
    points = values.get("free_points")
    if points is not None:
        if region is not None:
            problems.add("boundary.free_points", "give the moving control points either as a "
                                                 "box (free_region) or as a list (free_points), "
                                                 "not both")
        elif not points:
            problems.add("boundary.free_points", "is empty; list at least one [i, j] or leave "
                                                 "the key out (then all control points move)")
    return BoundarySpec(**values, **box)


def _validate_loads(raw: Mapping[str, Any], problems: _Problems,
                    solve: SolveSpec | None) -> tuple[LoadSpec, ...]:
    tables = raw.get("load", [])
    if isinstance(tables, dict):
        problems.add("load", "write loads as an array of tables: [[load]] (double brackets)")
        return ()
    if not isinstance(tables, list):
        problems.add("load", f"expected [[load]] tables, got {_describe(tables)}")
        return ()
    if not tables and solve is not None and solve.kind != "modes":
        problems.add("load", f"a {solve.kind} solve needs at least one [[load]] table")
    return tuple(spec for i, table in enumerate(tables, start=1)
                 if (spec := _validate_load(table, f"load[{i}]", problems)) is not None)


def _validate_load(table: Any, path: str, problems: _Problems) -> LoadSpec | None:
    values = _check_table(table, LOAD_KEYS, path, problems, "[load]")
    _require(values, table, ["kind"], LOAD_KEYS, path, problems)
    kind, profile = values.get("kind"), values.get("profile", "constant")
    if kind is None:
        return None
    _require(values, table, LOAD_KIND_KEYS[kind], LOAD_KEYS, path, problems,
             f" (a {kind} load needs it)")
    _not_applicable(table, ("at", "force", "q"), LOAD_KIND_KEYS[kind], path, problems,
                    f"to a {kind} load (it uses {', '.join(LOAD_KIND_KEYS[kind])})")
    used = PROFILE_KEYS[profile]
    _not_applicable(table, ("t_on", "t_off", "points", "omega", "phase"), used, path, problems,
                    f"to profile {profile!r}" + (f" (it uses {', '.join(used)})" if used else ""))
    needed = {"piecewise": ["points"], "harmonic": ["omega"]}.get(profile, [])
    _require(values, table, needed, LOAD_KEYS, path, problems, f" (profile {profile!r} needs it)")
    if profile == "step" and values.get("t_off", math.inf) <= values.get("t_on", 0.0):
        problems.add(f"{path}.t_off", f"must be > t_on = {values.get('t_on', 0.0):g}, got "
                                      f"{values['t_off']:g}")
    if "points" in values:
        times = [t for t, _ in values["points"]]
        bad = _first_not_increasing(times)
        if bad is not None:
            problems.add(f"{path}.points[{bad}]", f"times must be >= 0 and increasing, got "
                                                  f"{times}")
    if "at" in values:
        if any(x < 0 for x in values["at"]):
            problems.add(f"{path}.at", f"parameters must be >= 0, got {list(values['at'])}")
    if values.get("q") == 0 or ("force" in values and not any(values["force"])):
        problems.add(f"{path}.{'q' if kind == 'pressure' else 'force'}",
                     "is zero: this load does nothing; remove the [[load]] table or give a "
                     "non-zero value")
    given = [k for k in LOAD_KEYS if k != "kind"]
    return LoadSpec(kind=kind, **_with_defaults(LOAD_KEYS, values, given))


def _first_not_increasing(times: Iterable[float]) -> int | None:
    """Index (from 1) of the first time that is negative or not above the one before."""
    previous = -math.inf
    for i, t in enumerate(times, start=1):
        if t < 0 or t <= previous:
            return i
        previous = t
    return None


def _validate_solve(raw: Mapping[str, Any], problems: _Problems,
                    physics: str = "parametric") -> SolveSpec | None:
    if "solve" not in raw:
        problems.add("solve", f"missing table [solve]; it needs kind = "
                              f"{SOLVE_KEYS['kind'].allowed}")
        return None
    table = raw["solve"]
    values = _check_table(table, SOLVE_KEYS, "solve", problems, "solve")
    _require(values, table, ["kind"], SOLVE_KEYS, "solve", problems)
    kind = values.get("kind")
    if kind is None:
        return None
    used = SOLVE_KIND_KEYS[kind]
    _not_applicable(table, SOLVE_KEYS, ("kind",) + used, "solve", problems,
                    f"to kind {kind!r}" + (f" (it uses {', '.join(used)})" if used else ""))
    if kind == "dynamic":
        _check_dynamic(table, values, problems)
        if physics == "shell" and values.get("method", "analytic") != "analytic":
            problems.add("solve.method", f"the shell (physics \"shell\") is solved in closed "
                                         f"form only: method \"analytic\", got "
                                         f"{values['method']!r}")
    if kind == "modes" and values.get("modes", 1) < 1:
        problems.add("solve.modes", f"a modes solve needs modes >= 1, got {values['modes']}")
    return SolveSpec(kind=kind, **_with_defaults(SOLVE_KEYS, values,
                                                 [k for k in SOLVE_KEYS if k != "kind"]))


def _check_dynamic(table: Mapping[str, Any], values: dict[str, Any], problems: _Problems) -> None:
    method = values.get("method", "analytic")
    if "frames" in table and "times" in table:
        problems.add("solve.times", "give either frames or times, not both")
    if "t_end" not in table and "times" not in table:
        problems.add("solve.t_end", f"missing (a dynamic solve needs an end time); expected "
                                    f"{SOLVE_KEYS['t_end'].allowed}")
    times = values.get("times")
    if times is not None:
        bad = _first_not_increasing(times)
        if bad is not None:
            problems.add(f"solve.times[{bad}]", f"times must be increasing, got {list(times)}")
        if "t_end" in values and times[-1] > values["t_end"]:
            problems.add("solve.times", f"times must be <= t_end = {values['t_end']:g}, "
                                        f"got {times[-1]:g}")
        values.setdefault("t_end", times[-1] if times[-1] > 0 else None)
        if values["t_end"] is None:
            problems.add("solve.times", "needs a time > 0")
    for keys in (("rtol", "atol"), ("dt",), ("function_samples",)):
        methods = METHOD_SETTINGS[keys[0]]
        _not_applicable(table, keys, keys if method in methods else (), "solve", problems,
                        f"to method {method!r} (only to {', '.join(methods)})")


def _validate_output(raw: Mapping[str, Any], problems: _Problems,
                     solve: SolveSpec | None) -> OutputSpec | None:
    table = raw.get("output", {})
    values = _check_table(table, OUTPUT_KEYS, "output", problems, "output")
    if "formats" in values:
        expanded: list[str] = []
        for name in values["formats"]:
            for f in FORMAT_ALIASES.get(name, (name,)):
                if f not in expanded:
                    expanded.append(f)
        values["formats"] = tuple(expanded)
    if "time" in values and solve is not None:
        if solve.kind != "dynamic":
            problems.add("output.time", f"does not apply to a {solve.kind} solve (only dynamic)")
        elif solve.t_end is not None and values["time"] > solve.t_end:
            problems.add("output.time", f"must be <= t_end = {solve.t_end:g}, got "
                                        f"{values['time']:g}")
    if "animate_modes" in values and solve is not None:
        if solve.kind != "modes":
            problems.add("output.animate_modes",
                         f"does not apply to a {solve.kind} solve (only modes)")
        for i, k in enumerate(values["animate_modes"], start=1):
            if k > solve.modes:
                problems.add(f"output.animate_modes[{i}]",
                             f"mode {k} is not computed: solve.modes = {solve.modes}")
    for i, probe in enumerate(values.get("probes", ()), start=1):
        if len(probe) == 2 and min(probe) < 0:
            problems.add(f"output.probes[{i}]", "parameters must be >= 0, got "
                                                f"[{probe[0]:g}, {probe[1]:g}]")
    return OutputSpec(**values)


