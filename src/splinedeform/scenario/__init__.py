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

- :mod:`.locate` — the line of every key path in a TOML text, and problems reported there;
- :mod:`.checks` — value checkers (number, integer, choice, vector, …);
- :mod:`.keys` — the documented keys of every table: checker, default, meaning;
- :mod:`.spec` — the validated scenario (one frozen dataclass per table);
- :mod:`.read` — TOML text → validated :class:`Scenario`, with the cross-field rules;
- :mod:`.write` — a scenario back as TOML, every default filled in;
- :mod:`.build` — scenario → surface, model, load.

Adding a key: declare it in the table of :mod:`.keys` (checker, default, doc line), add
the field to the dataclass of :mod:`.spec`, document it in ``docs/scenario.md``, and, if it
only applies to some kinds, list it in the ``*_KIND_KEYS`` of :mod:`.keys`. A new shape is
one entry of ``SHAPE_PARAMETERS`` (its parameters are passed to ``splinedeform.shapes``);
a new time integrator is one entry of ``splinedeform.model.METHODS``.
"""

from __future__ import annotations

from .build import Built, _located, build, build_load, build_surface, describe, free_region_mask
from .checks import Key
from .keys import (FORMAT_ALIASES, FORMATS, IVP_METHODS, LOAD_KIND_KEYS, LOAD_KINDS,
                   MASS_MATRICES, PROFILE_KEYS, PROFILES, SHAPE_PARAMETERS, SHAPES, SOLVE_KIND_KEYS,
                   SOLVE_KINDS, TABLES, TOP_KEYS, documented_keys)
from .locate import key_lines
from .read import load_scenario, parse_scenario, with_overrides
from .spec import (BoundarySpec, LoadSpec, MaterialSpec, OutputSpec, Scenario, SolveSpec,
                   SurfaceSpec)
from .write import _toml_value, scenario_to_toml

__all__ = ["Built", "Key", "Scenario", "SurfaceSpec", "MaterialSpec", "BoundarySpec", "LoadSpec",
           "SolveSpec", "OutputSpec", "build", "build_load", "build_surface", "describe",
           "documented_keys", "free_region_mask", "key_lines", "load_scenario",
           "parse_scenario", "scenario_to_toml", "with_overrides"]
