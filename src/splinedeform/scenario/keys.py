"""The keys of a scenario file, per table: checker, default and meaning of each.

Derived from the pydantic models of :mod:`.schema` (the one place where a key's type,
constraints, default and description are written) in the shape the reader walks: one
``{name: Key}`` table per TOML table, plus which keys apply to which kind.
"""

from __future__ import annotations

import math

from ..boundary import EDGES
from ..model import STEP_METHODS  # noqa: F401  (re-exported for the reader)
from . import schema as S
from .checks import Key, choice, key_of, located_checker
from .schema import (FORMAT_ALIASES, FORMATS, IVP_METHODS, LOAD_KINDS,  # noqa: F401
                     MASS_MATRICES, PROFILES, SHAPES, SOLVE_KINDS, TIME_MAX)


def _keys(model: type, names: tuple[str, ...] | None = None, **defaults: object) -> dict[str, Key]:
    fields = model.model_fields
    return {name: key_of(fields[name], **({"default": defaults[name]} if name in defaults
                                          else {}), pair=name in ("size", "cells"))
            for name in (tuple(fields) if names is None else names)}


def _table_value(value: object) -> object:
    """The free region is checked key by key as a table of its own (FREE_REGION_KEYS)."""
    return value


_table_value.allowed = "an inline table"  # type: ignore[attr-defined]

_FITTED = tuple(S._Fitted.model_fields)

#: parameters of each built-in shape (passed to the function of ``splinedeform.shapes``)
SHAPE_PARAMETERS: dict[str, dict[str, Key]] = {
    shape: _keys(model, tuple(n for n in model.model_fields
                              if n not in (*_FITTED, "shape", "path", "frame")))
    for shape, model in zip(SHAPES, S.SHAPE_MODELS)}

SURFACE_KEYS: dict[str, Key] = {
    "shape": Key(choice(*SHAPES), doc="a built-in shape, or a control net / point grid "
                                      "(`file`) or a CAD surface (`cad`) read from `path`"),
    **_keys(S.FromFile, (*_FITTED, "path", "frame"), path=None),
}
SURFACE_KEYS["trim"] = Key(located_checker(S.Trim, "{loops = [...]}"), None,
                           SURFACE_KEYS["trim"].doc, SURFACE_KEYS["trim"].shown_default)

MATERIAL_KEYS: dict[str, Key] = _keys(S.Material)

FREE_REGION_KEYS: dict[str, Key] = _keys(S.FreeRegion)

BOUNDARY_KEYS: dict[str, Key] = {
    **_keys(S.Boundary, EDGES),
    "free_region": Key(_table_value, None, S.Boundary.model_fields["free_region"].description),
    **_keys(S.Boundary, ("free_points",)),
    "faces": Key(located_checker(dict[S.FaceKey, S.FaceEdges], "{k = {u0 = ...}}"), None,
                 _keys(S.Boundary, ("faces",))["faces"].doc, "none"),
    "faces_free_points": Key(
        located_checker(dict[S.FaceKey, list[tuple[S.NetIndex, S.NetIndex]]],
                        "{k = [[i, j], ...]}"), None,
        _keys(S.Boundary, ("faces_free_points",))["faces_free_points"].doc, "none (all move)"),
    "loops": Key(located_checker(dict[S.LoopKey, S.LoopPresets], '{outer = "clamped"}'), None,
                 _keys(S.Boundary, ("loops",))["loops"].doc, "none (free)"),
}

_PROFILED = tuple(S._Profiled.model_fields)
LOAD_KEYS: dict[str, Key] = {
    "kind": Key(choice(*LOAD_KINDS), doc="a point force, a uniform force per area "
                                          "(gravity-like), a pressure along the initial normal"),
    **_keys(S.PointLoad, ("at", "force"), at=None, force=None),
    **_keys(S.PressureLoad, ("q",), q=None),
    **_keys(S._Profiled, _PROFILED, t_off=math.inf),
    **_keys(S._OnFace, ("face",), face=None),
}

#: load keys allowed for each kind and each profile
LOAD_KIND_KEYS = {kind: tuple(n for n in model.model_fields if n not in (*_PROFILED, "kind", "face"))
                  for kind, model in zip(LOAD_KINDS, S.LOAD_MODELS)}
PROFILE_KEYS = {"constant": (), "step": ("t_on", "t_off"), "piecewise": ("points",),
                "harmonic": ("omega", "phase")}

SOLVE_KEYS: dict[str, Key] = {
    "kind": Key(choice(*SOLVE_KINDS), doc="equilibrium `K d = F`, free vibration modes, or the "
                                           "motion from rest"),
    **_keys(S.DynamicSolve, tuple(n for n in S.DynamicSolve.model_fields if n != "kind")),
}

#: keys of [solve] that only some methods use: key -> the methods that use it
METHOD_SETTINGS: dict[str, tuple[str, ...]] = {
    "rtol": IVP_METHODS, "atol": IVP_METHODS, "dt": STEP_METHODS,
    "function_samples": ("analytic",),
}

#: keys of [solve] used by each kind
SOLVE_KIND_KEYS = {kind: tuple(n for n in model.model_fields if n != "kind")
                   for kind, model in zip(SOLVE_KINDS, S.SOLVE_MODELS)}

OUTPUT_KEYS: dict[str, Key] = _keys(S.Output)

TOP_KEYS: dict[str, Key] = _keys(S.ScenarioFile, ("title", "description"))

TABLES: dict[str, dict[str, Key]] = {
    "surface": SURFACE_KEYS, "material": MATERIAL_KEYS, "boundary": BOUNDARY_KEYS,
    "load": LOAD_KEYS, "solve": SOLVE_KEYS, "output": OUTPUT_KEYS,
}


def documented_keys() -> list[str]:
    """Every key path a scenario may contain, as listed in ``docs/scenario.md``.

    Array tables are written without index (``load.force``); shape parameters as
    ``surface.<name>``; the free region as ``boundary.free_region.u``.
    """
    keys = list(TOP_KEYS)
    for table, keys_of in TABLES.items():
        keys += [f"{table}.{k}" for k in keys_of]
    keys += [f"boundary.free_region.{k}" for k in FREE_REGION_KEYS]
    for params in SHAPE_PARAMETERS.values():
        keys += [f"surface.{k}" for k in params if f"surface.{k}" not in keys]
    return keys
