"""Scenario files: one TOML file describes one simulation.

A scenario has the tables ``[surface]``, ``[material]``, ``[boundary]``, ``[[load]]``,
``[solve]`` and ``[output]`` (every key is documented in ``docs/scenario.md``). Reading is
two steps:

1. :func:`load_scenario` / :func:`parse_scenario` read the text with :mod:`tomllib` and
   validate **every** field before any work starts. All problems found are reported
   together in one :class:`~splinedeform.errors.ScenarioError` whose lines read
   ``file:line: key.path: what is wrong; what is allowed``. ``tomllib`` gives no
   positions, so the line of each key is found by scanning the text (:func:`key_lines`).
2. :func:`build` turns a :class:`Scenario` into library objects (surface, model, load),
   and :func:`run` solves it and writes the requested outputs.

Arrays of tables and array elements are counted from 1: ``load[2].force`` is the
``force`` of the second ``[[load]]`` table.

Modules, one idea each:

- :mod:`.schema` — the scenario as typed pydantic models: every key's type, constraints,
  default and description, written once; ``splinedeform schema`` prints its JSON Schema;
- :mod:`.checks` — one key checked with pydantic, and what it allows said in words;
- :mod:`.keys` — the per-table key lists the reader walks, derived from the models;
- :mod:`.locate` — the line of every key path in a TOML text, problems reported there;
- :mod:`.validate` — every key checked, then the cross-field rules of the physics;
- :mod:`.spec` — the validated scenario (one frozen dataclass per table, used downstream);
- :mod:`.read` — TOML text (or file) → validated :class:`Scenario`;
- :mod:`.write` — a scenario back as TOML, every default filled in;
- :mod:`.build` — scenario → surface, model, load.

Adding a key: one field (type, constraints, default, ``description``) on the model of its
table in :mod:`.schema`; the field of the dataclass in :mod:`.spec` that carries it
downstream; its row in ``docs/scenario.md``; a cross-field rule in :mod:`.validate` if it
depends on other keys. A new shape is one model in ``schema.SHAPE_MODELS`` (its fields
are passed to the function of ``splinedeform.shapes`` of that name), a load or solve kind
one model in ``LOAD_MODELS`` / ``SOLVE_MODELS``, a time integrator one name in
``splinedeform.model.METHODS``; a choice between variants (such as a physics model) is a
``Literal`` field.
"""

from __future__ import annotations

from .build import Built, _located, build, build_load, build_surface, describe, free_region_mask
from .checks import Key
from .keys import (FORMAT_ALIASES, FORMATS, IVP_METHODS, LOAD_KIND_KEYS, LOAD_KINDS,
                   MASS_MATRICES, PROFILE_KEYS, PROFILES, SHAPE_PARAMETERS, SHAPES,
                   SOLVE_KIND_KEYS, SOLVE_KINDS, TABLES, TOP_KEYS, documented_keys)
from .locate import key_lines
from .read import load_scenario, parse_scenario, with_method, with_overrides
from .spec import (BoundarySpec, LoadSpec, MaterialSpec, OutputSpec, Scenario, SolveSpec,
                   SurfaceSpec)
from .write import _toml_value, scenario_to_toml

__all__ = ["Built", "Key", "Scenario", "SurfaceSpec", "MaterialSpec", "BoundarySpec", "LoadSpec",
           "SolveSpec", "OutputSpec", "build", "build_load", "build_surface", "describe",
           "documented_keys", "free_region_mask", "key_lines", "load_scenario",
           "parse_scenario", "scenario_to_toml", "with_method", "with_overrides"]
