"""Axis keys: a key path of the base scenario, checked against the scenario's keys, and set.

A path is dotted, with ``[[load]]`` tables counted from 1 as in scenario errors:
``material.w20``, ``surface.cells``, ``boundary.free_region.u``, ``load[2].at`` (also
written ``load.2.at``), or ``load.force`` for every ``[[load]]`` table.
"""

from __future__ import annotations

import copy
import re
from dataclasses import dataclass
from typing import Any, Mapping

from ..scenario.keys import FREE_REGION_KEYS, SHAPE_PARAMETERS, TABLES, TOP_KEYS

_INDEXED = re.compile(r"^load(?:\[(\d+)\]|\.(\d+))\.(.+)$")


class UnknownKey(ValueError):
    """An axis key the scenario files do not have (the message says what they have)."""


@dataclass(frozen=True)
class KeyPath:
    """A parsed axis key: table, ``[[load]]`` index (from 1, or None for every one), names."""

    table: str
    index: int | None
    names: tuple[str, ...]

    @property
    def path(self) -> str:
        """The key as scenario errors write it (``load[2].at``, ``material.w20``)."""
        head = self.table if self.index is None else f"{self.table}[{self.index}]"
        return ".".join((head, *self.names)) if self.table else ".".join(self.names)


def parse_key(key: str, n_loads: int) -> KeyPath:
    """The :class:`KeyPath` of ``key``, refused (:class:`UnknownKey`) unless scenarios have it.

    ``n_loads`` is the number of ``[[load]]`` tables of the base scenario: an index beyond
    it is refused.
    """
    indexed = _INDEXED.match(key)
    if indexed:
        index = int(indexed.group(1) or indexed.group(2))
        if not 1 <= index <= n_loads:
            raise UnknownKey(f"{key!r}: the base scenario has {n_loads} [[load]] table(s), "
                             "counted from 1")
        return _known(KeyPath("load", index, tuple(indexed.group(3).split("."))), key)
    parts = tuple(key.split("."))
    if len(parts) == 1:
        if parts[0] in TOP_KEYS:
            return KeyPath("", None, parts)
        raise UnknownKey(f"{key!r} is not a key of scenario files; a key path names its "
                         f"table: {', '.join(f'{t}.<key>' for t in TABLES)}")
    if parts[0] == "load" and n_loads == 0:
        raise UnknownKey(f"{key!r}: the base scenario has no [[load]] table")
    return _known(KeyPath(parts[0], None, parts[1:]), key)


def _known(path: KeyPath, key: str) -> KeyPath:
    table, names = path.table, path.names
    if table not in TABLES:
        raise UnknownKey(f"{key!r}: scenario files have no table [{table}]; tables: "
                         f"{', '.join(TABLES)}")
    allowed: dict[str, Any] = dict(TABLES[table])
    if table == "surface":
        allowed.update({k: v for params in SHAPE_PARAMETERS.values() for k, v in params.items()})
    if table == "boundary" and names[0] == "free_region" and len(names) == 2:
        if names[1] in FREE_REGION_KEYS:
            return path
        raise UnknownKey(f"{key!r}: boundary.free_region has the keys "
                         f"{', '.join(FREE_REGION_KEYS)}")
    if len(names) != 1 or names[0] not in allowed:
        raise UnknownKey(f"{key!r} is not a key of [{table}]; its keys: {', '.join(allowed)}")
    return path


def with_values(raw: Mapping[str, Any], values: Mapping[KeyPath, Any]) -> dict[str, Any]:
    """A copy of the scenario tables ``raw`` with each key path set to its value."""
    out = copy.deepcopy(dict(raw))
    for path, value in values.items():
        if not path.table:
            out[path.names[0]] = copy.deepcopy(value)
            continue
        if path.table == "load":
            loads = [t for t in out.get("load", []) if isinstance(t, dict)]
            targets = loads if path.index is None else [loads[path.index - 1]]
        else:
            table = out.setdefault(path.table, {})
            targets = [table] if isinstance(table, dict) else []
        for target in targets:
            for name in path.names[:-1]:
                target = target.setdefault(name, {})
            target[path.names[-1]] = copy.deepcopy(value)
    return out
