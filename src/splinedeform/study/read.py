"""Reading a sweep file: TOML text → validated :class:`Sweep`, problems located at their lines.

The reading steps are the scenario reader's (:func:`splinedeform.scenario.read.read_toml`,
:func:`~splinedeform.scenario.locate.key_lines`, the per-key checks of
:func:`~splinedeform.scenario.validate._check_table`); this module adds the sweep's own
keys (:mod:`.schema`) and rules: one of ``values`` / ``range`` per axis, ``count`` on a
grid, ``n`` for random designs, and every axis key known to scenario files.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..errors import ScenarioError
from ..scenario import Scenario, load_scenario
from ..scenario.checks import Key, key_of
from ..scenario.locate import _Problems, key_lines
from ..scenario.read import read_toml
from ..scenario.validate import _check_table, top_level
from . import schema as S
from .keys import KeyPath, UnknownKey, parse_key


def _keys(model: type) -> dict[str, Key]:
    return {name: key_of(field, default=None) if name in ("values", "range", "count", "n")
            else key_of(field) for name, field in model.model_fields.items()}


TOP_KEYS = {name: key_of(S.SweepFile.model_fields[name])
            for name in ("title", "description", "scenario")}
AXIS_KEYS = _keys(S.Axis)
DESIGN_KEYS = _keys(S.Design)
OUTPUT_KEYS = _keys(S.SweepOutput)
TABLES = ("design", "axis", "output")


@dataclass(frozen=True)
class AxisSpec:
    """One validated ``[[axis]]``: its key and either its ``values`` or its ``range``."""

    key: str
    path: KeyPath
    values: tuple[Any, ...] | None = None
    range: tuple[float, float] | None = None
    count: int | None = None
    scale: str = "linear"
    integer: bool = False


@dataclass(frozen=True)
class Sweep:
    """A validated sweep file; run it with :func:`splinedeform.sweep`."""

    base: Scenario
    axes: tuple[AxisSpec, ...]
    design: str = "grid"
    n: int | None = None
    seed: int = 0
    cases_output: bool = False
    plots: bool = True
    title: str = ""
    description: str = ""
    source: str = "<sweep>"
    directory: Path = Path(".")


class _SweepProblems(_Problems):
    def message(self) -> str:
        text = super().message()
        return text.replace("problems in the scenario", "problems in the sweep file", 1)


def load_sweep(path: str | Path) -> Sweep:
    """Read and validate a sweep file and its base scenario.

    Raises
    ------
    ScenarioError
        With every problem of the sweep file, each as ``file:line: key.path: message``, or
        the base scenario's own problems.
    """
    path = Path(path)
    try:
        content = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise ScenarioError(f"{path}: sweep file not found") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise ScenarioError(f"{path}: cannot read the sweep file ({exc})") from None
    return parse_sweep(content, source=str(path), directory=path.parent.resolve())


def parse_sweep(content: str, source: str = "<sweep>", directory: Path | None = None) -> Sweep:
    """Validate the TOML text of a sweep file (see :func:`load_sweep`)."""
    directory = directory or Path.cwd()
    raw = read_toml(content, source)
    problems = _SweepProblems(source, key_lines(content))
    top = top_level(raw, TOP_KEYS, TABLES, ["[design]", "[[axis]]", "[output]"], problems)
    if "scenario" not in raw:
        problems.add("scenario", f"missing; expected {TOP_KEYS['scenario'].allowed}: the base "
                                 "scenario file, relative to the sweep file")
    design = _check_table(raw.get("design", {}), DESIGN_KEYS, "design", problems, "design")
    output = _check_table(raw.get("output", {}), OUTPUT_KEYS, "output", problems, "output")
    kind = design.get("kind", "grid")
    if kind == "grid" and design.get("n") is not None:
        problems.add("design.n", "does not apply to a grid (its cases are every combination "
                                 "of the axes' values); give each axis values or count")
    if kind != "grid" and "n" not in raw.get("design", {}):
        problems.add("design.n", f"missing: a {kind} design draws n cases")
    given = _axes(raw.get("axis"), kind, problems)
    base = _base_scenario(top.get("scenario"), directory, problems)
    axes = _axis_keys(given, base, problems)
    problems.raise_if_any()
    assert base is not None
    return Sweep(base=base, axes=tuple(axes), design=kind, n=design.get("n"),
                 seed=design.get("seed", 0), cases_output=output.get("cases", False),
                 plots=output.get("plots", True), title=top.get("title", ""),
                 description=top.get("description", ""), source=source, directory=directory)


def _base_scenario(name: str | None, directory: Path, problems: _Problems) -> Scenario | None:
    if name is None:
        return None
    path = (directory / name).resolve()
    if not path.is_file():
        problems.add("scenario", f"the base scenario {str(path)!r} is not a file (a path "
                                 "relative to the sweep file)")
        return None
    problems.raise_if_any()          # the sweep's own problems first
    return load_scenario(path)       # the base scenario's problems are located in its file


def _axes(raw: Any, kind: str, problems: _Problems) -> list[tuple[str, dict[str, Any]]]:
    """The checked values of each ``[[axis]]`` table, with its key path (``axis[i]``)."""
    if raw is None:
        problems.add("axis", "missing: a sweep needs at least one [[axis]] table "
                             "(key = \"material.w20\", values = [...])")
        return []
    if not isinstance(raw, list):
        problems.add("axis", "expected [[axis]] tables (an array of tables)")
        return []
    axes = []
    for i, table in enumerate(raw, start=1):
        where = f"axis[{i}]"
        values = _check_table(table, AXIS_KEYS, where, problems, "axis")
        if not isinstance(table, dict):
            continue
        if "key" not in table:
            problems.add(f"{where}.key", "missing; expected the scenario key this axis varies "
                                         "(\"material.w20\")")
        given = [k for k in ("values", "range") if k in table]
        if len(given) != 1:
            problems.add(where, "give exactly one of values = [...] or range = [low, high]"
                         + (" (both given)" if len(given) == 2 else ""))
        if "range" not in table:
            for key in ("count", "scale", "integer"):
                if key in table:
                    problems.add(f"{where}.{key}", "applies to range only")
        low_high = values.get("range")
        if low_high is not None:
            low, high = low_high
            if not low < high:
                problems.add(f"{where}.range", f"expected low < high, got [{low:g}, {high:g}]")
            if values.get("scale") == "log" and low <= 0:
                problems.add(f"{where}.range", "a log scale needs low > 0")
            if kind == "grid" and "count" not in table:
                problems.add(f"{where}.count", "missing: a grid needs the number of values of "
                                               "the range")
            if kind != "grid" and "count" in table:
                problems.add(f"{where}.count", f"does not apply to a {kind} design (it draws "
                                               "design.n values)")
        axes.append((where, values))
    return axes


def _axis_keys(given: list[tuple[str, dict[str, Any]]], base: Scenario | None,
               problems: _Problems) -> list[AxisSpec]:
    """Each axis whose key the base scenario's schema knows; the others refused by name."""
    axes: list[AxisSpec] = []
    seen: dict[str, str] = {}
    for where, values in given:
        key = values.get("key")
        if key is None or base is None:
            continue
        try:
            path = parse_key(key, len(base.loads))
        except UnknownKey as exc:
            problems.add(f"{where}.key", f"axis {key!r} is refused: {exc}")
            continue
        if path.path in seen:
            problems.add(f"{where}.key", f"axis {key!r} is already varied by {seen[path.path]}")
            continue
        seen[path.path] = where
        axes.append(AxisSpec(key=path.path, path=path, values=values.get("values"),
                             range=values.get("range"), count=values.get("count"),
                             scale=values.get("scale", "linear"),
                             integer=values.get("integer", False)))
    return axes
