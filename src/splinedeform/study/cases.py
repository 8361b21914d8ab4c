"""The cases of a sweep: each design point as a validated scenario, its content hash and model.

A case is the base scenario with the axes' keys set (:func:`.keys.with_values`) and
validated again by the scenario reader: a value a key does not allow makes the case fail
with the reader's located message (``base.toml (axis material.w20 = -1): material.w20:
expected a number >= 0, got …``), and the sweep goes on.

Two hashes name a case:

- ``hash``: SHA-256 of its content (every scenario table after the axes are set, the
  files it reads, the package version): a case whose result is stored under this name
  in the output folder is not computed again;
- ``model``: SHA-256 of what its :class:`~splinedeform.Model` is built from (``[surface]``,
  ``[material]``, ``[boundary]`` and the files they read): cases with equal ``model``
  differ only in loads, solve or output keys and share one model, its modal basis
  computed once;
- ``geometry``: SHA-256 of the same less the material's weights (``mass``, ``damping``,
  ``rayleigh``, ``w10`` … ``w02``): models of equal ``geometry`` share their surface,
  constraints and 1-D Gram matrices on a worker (:mod:`.geometries`).
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from .. import __version__
from ..errors import ScenarioError
from ..scenario import Scenario
from ..scenario.validate import _validate
from .design import design_points
from .keys import KeyPath, with_values
from .read import Sweep

#: the scenario tables a model is built from
MODEL_TABLES = ("surface", "material", "boundary")
#: the keys of ``[material]`` that weight the 1-D Gram matrices (and nothing else)
WEIGHT_KEYS = ("mass", "damping", "rayleigh", "w10", "w01", "w20", "w11", "w02")


@dataclass(frozen=True)
class Case:
    """One case: its axis values, its hashes and its scenario (or why it has none)."""

    index: int                      # position in the design, from 1
    values: dict[str, Any]          # axis key -> value
    hash: str
    model: str
    scenario: Scenario | None
    error: str | None = None        # the reader's message when the values are refused
    geometry: str = ""              # the model's hash less the material's weights


def plan_cases(sweep: Sweep) -> list[Case]:
    """Every case of the sweep's design, in design order, validated."""
    base = sweep.base
    paths: dict[str, KeyPath] = {axis.key: axis.path for axis in sweep.axes}
    files = _files_read(base)
    cases = []
    for index, point in enumerate(design_points(sweep), start=1):
        raw = with_values(base.raw, {paths[key]: value for key, value in point.items()})
        origins = dict(base.origins)
        for key, value in point.items():
            origin = f"axis {key} = {json.dumps(value)}"
            for where in _reported_at(paths[key], len(base.loads)):
                origins[where] = origin
        content = {"version": __version__, "directory": str(base.directory), "files": files}
        tables = {t: raw.get(t) for t in MODEL_TABLES}
        model = _digest({**content, **tables})
        material = tables["material"]
        geometry = _digest({**content, **tables, "material": {
            k: v for k, v in material.items() if k not in WEIGHT_KEYS}
            if isinstance(material, dict) else material})
        digest = _digest({**content, "scenario": raw})
        try:
            scenario = _validate(raw, base.source, base.lines, origins, base.directory,
                                 base.allow_outside_paths)
        except ScenarioError as exc:
            cases.append(Case(index, point, digest, model, None, str(exc), geometry))
            continue
        cases.append(Case(index, point, digest, model, scenario, geometry=geometry))
    return cases


def _reported_at(path: KeyPath, n_loads: int) -> list[str]:
    """The key paths at which the reader reports a problem with ``path``'s value."""
    if path.table == "load" and path.index is None:
        return [f"load[{i}].{'.'.join(path.names)}" for i in range(1, n_loads + 1)]
    return [path.path]


def _files_read(scenario: Scenario) -> dict[str, str]:
    """SHA-256 of each file the scenario reads (``surface.path``)."""
    name = scenario.raw.get("surface", {}).get("path")
    if not isinstance(name, str):
        return {}
    path = Path(scenario.directory) / name
    try:
        return {name: hashlib.sha256(path.read_bytes()).hexdigest()}
    except OSError:
        return {name: "unreadable"}


def _digest(content: Any) -> str:
    text = json.dumps(content, sort_keys=True, default=repr, ensure_ascii=True)
    return hashlib.sha256(text.encode("utf-8")).hexdigest()
