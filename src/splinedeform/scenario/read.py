"""Reading a scenario: TOML text → validated :class:`~.spec.Scenario`."""

from __future__ import annotations

import copy
import re
import tomllib
from pathlib import Path
from typing import Any, Mapping

from ..errors import InputError, ScenarioError
from ..input_files import read_input_text
from ..model import METHODS
from .keys import METHOD_SETTINGS
from .locate import MAX_NESTING, key_lines, nesting_too_deep
from .spec import Scenario
from .validate import _validate


# -- reading ---------------------------------------------------------------------------
def load_scenario(path: str | Path, overrides: Mapping[str, Any] | None = None,
                  origin: str = "override", allow_outside_paths: bool = False) -> Scenario:
    """Read and validate a scenario file.

    Parameters
    ----------
    path : str or Path
        The TOML file. Relative file names inside it (``surface.path``) are resolved
        against its folder.
    overrides : mapping, optional
        ``{"solve.frames": 5, "surface.cells": 4}``: values replacing (or, for ``None``,
        removing) keys of the file before validation; problems with them are reported as
        coming from ``origin``.
    allow_outside_paths : bool
        Files named in the scenario (``surface.path``) must lie inside the scenario's
        folder (after following ``..`` and symbolic links) unless this is True: scenario
        files are shared, and a shared file must not read whatever its user can read.

    Raises
    ------
    ScenarioError
        With every problem found, each as ``file:line: key.path: message``.
    """
    path = Path(path)
    try:
        content = read_input_text(path, "scenario file")
    except InputError as exc:
        raise ScenarioError(str(exc)) from None
    except OSError as exc:
        raise ScenarioError(f"{path}: cannot read the scenario file ({exc})") from None
    return parse_scenario(content, source=str(path), directory=path.parent.resolve(),
                          overrides=overrides, origin=origin,
                          allow_outside_paths=allow_outside_paths)


def parse_scenario(content: str, source: str = "<scenario>", directory: Path | None = None,
                   overrides: Mapping[str, Any] | None = None,
                   origin: str = "override", allow_outside_paths: bool = False) -> Scenario:
    """Validate the TOML text of a scenario (see :func:`load_scenario`); a leading UTF-8
    byte order mark (as some editors write) is dropped."""
    content = content.removeprefix("\ufeff")
    deep = nesting_too_deep(content)
    if deep is not None:
        raise ScenarioError(f"{source}:{deep}: arrays or inline tables nested more than "
                            f"{MAX_NESTING} deep; a scenario needs at most 3 levels")
    try:
        raw = tomllib.loads(content)
    except RecursionError:   # belt and braces: nesting_too_deep should have caught it
        raise ScenarioError(f"{source}: arrays or inline tables nested too deep") from None
    except tomllib.TOMLDecodeError as exc:
        match = re.search(r"\(at line (\d+), column (\d+)\)", str(exc))
        reason = re.sub(r"\s*\(at line \d+, column \d+\)", "", str(exc))
        where = f"{source}:{match.group(1)}" if match else source
        column = f" (column {match.group(2)})" if match else ""
        raise ScenarioError(f"{where}: TOML syntax error{column}: {reason}") from None
    lines = key_lines(content)
    origins: dict[str, str] = {}
    if overrides:
        raw = _apply_overrides(raw, overrides)
        origins = {key: origin for key in overrides}
    return _validate(raw, source, lines, origins, directory or Path.cwd(), allow_outside_paths)


def with_overrides(scenario: Scenario, overrides: Mapping[str, Any],
                   origin: str = "override") -> Scenario:
    """A copy of ``scenario`` with keys replaced (``None`` removes a key), validated again.

    Keys are ``"table.key"`` (``"solve.frames"``) or top-level names; a key of
    ``load`` applies to every ``[[load]]`` table.
    """
    raw = _apply_overrides(scenario.raw, overrides)
    origins = {**scenario.origins, **{key: origin for key in overrides}}
    return _validate(raw, scenario.source, scenario.lines, origins, scenario.directory,
                     scenario.allow_outside_paths)


def with_method(scenario: Scenario, method: str, origin: str = "--method"
                ) -> tuple[Scenario, list[str]]:
    """A copy of ``scenario`` solved with another method, without the old method's settings.

    The keys of ``[solve]`` that only some methods use (``rtol``/``atol`` of the
    ``solve_ivp`` methods, ``dt`` of the fixed-step methods, ``function_samples`` of the
    analytic one, see :data:`.keys.METHOD_SETTINGS`) are removed when ``method`` does not
    use them, so that a file written for one method runs with any other.

    Returns
    -------
    scenario : Scenario
        Validated again; problems are reported as coming from ``origin``.
    dropped : list of str
        The key paths removed (``["solve.rtol", "solve.atol"]``), for the caller to say.
    """
    solve = scenario.raw.get("solve")
    dropped = []
    if isinstance(solve, dict) and method in METHODS:
        dropped = [f"solve.{key}" for key, methods in METHOD_SETTINGS.items()
                   if key in solve and method not in methods]
    overrides: dict[str, Any] = {"solve.method": method, **{key: None for key in dropped}}
    return with_overrides(scenario, overrides, origin=origin), dropped


def _apply_overrides(raw: Mapping[str, Any], overrides: Mapping[str, Any]) -> dict[str, Any]:
    out = copy.deepcopy(dict(raw))
    for key, value in overrides.items():
        table, _, name = key.rpartition(".")
        targets: list[dict[str, Any]]
        if not table:
            targets = [out]
        elif table == "load":
            targets = [t for t in out.get("load", []) if isinstance(t, dict)]
        else:
            if not isinstance(out.get(table, {}), dict):
                raise InputError(f"cannot override {key}: [{table}] is not a table")
            targets = [out.setdefault(table, {})]
        for target in targets:
            if value is None:
                target.pop(name, None)
            else:
                target[name] = copy.deepcopy(value)
    return out


