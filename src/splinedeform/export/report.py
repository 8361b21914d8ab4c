"""report.json (every value) and report.md (tables) of a run."""

from __future__ import annotations

import html
import json
import math
import os
import re
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import InputError
from .atomic import _require_folder, write_text

REPORT_TABLE_ROWS = 41
SAFE_SCHEMES = frozenset({"http", "https", "mailto"})
"""URL schemes a link of report.md may keep; any other (``javascript:``, ``data:``, …) is defused."""

# a link destination: after "](" (inline link or image) or "]:" (reference definition),
# optionally opened by "<" (escaped to "&lt;" by then), up to the next space or ")"
_DESTINATION = re.compile(r"(\]\s*)(\(|:)(\s*(?:&lt;)?)([^\s)]*)")
_SCHEME = re.compile(r"([a-z][a-z0-9+.\-]*):")
# a scheme anywhere in the text (a bare "javascript:alert(1)" that some renderer might link)
_ANY_SCHEME = re.compile(r"(?<![a-z0-9+.\-])([a-z][a-z0-9+.\-]*)(\\?):", re.IGNORECASE)
_ALWAYS_DEFUSED = frozenset({"javascript", "vbscript", "data", "file", "livescript"})


def _scheme(destination: str) -> str | None:
    """The scheme a browser would read in a link destination, lower case (None: relative).

    As a renderer and a browser read it: HTML entities decoded, backslash escapes dropped,
    and ASCII controls and spaces removed (a browser's URL parser strips them).
    """
    text = html.unescape(destination).replace("\\", "")
    text = "".join(c for c in text if c > " " and c != "\x7f").lower()
    match = _SCHEME.match(text)
    return match.group(1) if match else None


def defuse_links(text: str) -> str:
    """``text`` (already HTML-escaped) with every link whose scheme is not in
    :data:`SAFE_SCHEMES` turned into plain text.

    ``[a](javascript:x)`` becomes ``[a]\\(javascript&#58;x)``: the escaped parenthesis
    (``]\\:`` for a reference definition) leaves no link, and the colon of a dangerous
    scheme is written as a character reference wherever it appears, so no renderer reads
    the scheme. Relative links and ``http``, ``https``, ``mailto`` are kept as they are.
    Autolinks ``<javascript:x>`` and raw HTML cannot occur: ``<`` is already ``&lt;``.
    """
    def destination(match: re.Match[str]) -> str:
        scheme = _scheme(match.group(4))
        if scheme is None or scheme in SAFE_SCHEMES:
            return match.group(0)
        return match.group(1) + "\\" + "".join(match.group(2, 3, 4))

    def bare(match: re.Match[str]) -> str:
        if match.group(1).lower() not in _ALWAYS_DEFUSED:
            return match.group(0)
        return match.group(1) + "&#58;"

    return _ANY_SCHEME.sub(bare, _DESTINATION.sub(destination, text))


def plain(value: Any) -> Any:
    """``value`` with numpy scalars/arrays, paths and tuples turned into JSON types.

    Non-finite floats become the strings ``"inf"``, ``"-inf"`` and ``"nan"`` (JSON has
    no such numbers).
    """
    if isinstance(value, Mapping):
        return {str(k): plain(v) for k, v in value.items()}
    if isinstance(value, np.ndarray):
        return plain(value.tolist())
    if isinstance(value, (list, tuple, set, frozenset)):
        return [plain(v) for v in value]
    if isinstance(value, np.generic):
        return plain(value.item())
    if isinstance(value, float):
        return value if math.isfinite(value) else str(value)
    if isinstance(value, complex):
        return {"real": plain(value.real), "imag": plain(value.imag)}
    if isinstance(value, (str, int, bool)) or value is None:
        return value
    if isinstance(value, os.PathLike):
        return os.fspath(value)
    raise InputError(f"report values must be numbers, strings, lists, mappings, arrays or "
                     f"paths; got {type(value).__name__}")


def format_value(value: Any) -> str:
    """A cell of report.md: floats with 6 significant digits (``{:.6g}``), lists joined."""
    if isinstance(value, bool) or value is None:
        return str(value)
    if isinstance(value, float):
        return f"{value:.6g}"
    if isinstance(value, list):
        return "[" + ", ".join(format_value(v) for v in value) + "]"
    if isinstance(value, dict):
        return ", ".join(f"{k}={format_value(v)}" for k, v in value.items())
    # text from a scenario (its title, a net's name) is shown, never interpreted: HTML
    # escaped, on one line (any whitespace, also U+2028, is one space), pipes escaped,
    # links of any scheme but http, https and mailto defused
    return defuse_links(html.escape(" ".join(str(value).split()))).replace("|", "\\|")


def _is_scalar(value: Any) -> bool:
    return not isinstance(value, (dict, list))


def _table(header: Sequence[str], rows: Sequence[Sequence[Any]]) -> list[str]:
    lines = ["| " + " | ".join(map(format_value, header)) + " |", "|" + "---|" * len(header)]
    return lines + ["| " + " | ".join(format_value(c) for c in row) + " |" for row in rows]


def _thin(n: int) -> list[int]:
    """Row indices kept in a long table: evenly spaced, first and last included."""
    if n <= REPORT_TABLE_ROWS:
        return list(range(n))
    return sorted(set(np.linspace(0, n - 1, REPORT_TABLE_ROWS).round().astype(int).tolist()))


def _columns_table(section: dict[str, list[Any]]) -> list[str]:
    n = len(next(iter(section.values())))
    keep = _thin(n)
    lines = _table(list(section), [[section[k][i] for k in section] for i in keep])
    if len(keep) < n:
        lines.append(f"\n{len(keep)} of {n} rows shown; every row is in report.json.")
    return lines


def _flatten(section: dict[str, Any], prefix: str = "") -> list[tuple[str, Any]]:
    rows: list[tuple[str, Any]] = []
    for key, value in section.items():
        if isinstance(value, dict) and value:
            rows += _flatten(value, f"{prefix}{key}.")
        else:
            rows.append((f"{prefix}{key}", value))
    return rows


def section_markdown(section: Any) -> list[str]:
    """Markdown for one report section.

    * equal-length lists of scalars under every key → one column per key (a time table,
      long ones thinned to about 40 rows);
    * a mapping of mappings with scalar values → one row per outer key, one column per
      inner key (e.g. probes);
    * any other mapping → a ``key | value`` table with nested keys joined by dots;
    * a list of mappings → one row per item; anything else → the value itself.
    """
    if isinstance(section, dict) and section:
        values = list(section.values())
        if all(isinstance(v, list) and v and all(map(_is_scalar, v)) for v in values) \
                and len({len(v) for v in values}) == 1:
            return _columns_table(section)
        if all(isinstance(v, dict) and v and all(map(_is_scalar, v.values())) for v in values):
            columns = list(dict.fromkeys(k for v in values for k in v))
            return _table(["", *columns], [[name, *(v.get(c, "") for c in columns)]
                                           for name, v in section.items()])
        return _table(["key", "value"], _flatten(section))
    if isinstance(section, list) and section and all(isinstance(v, dict) for v in section):
        columns = list(dict.fromkeys(k for v in section for k in v))
        return _table(columns, [[v.get(c, "") for c in columns] for v in section])
    return [format_value(section)]


def report_markdown(report: Mapping[str, Any], title: str = "splinedeform report") -> str:
    """report.md: a heading and a table (see :func:`section_markdown`) per top-level key."""
    doc = plain(report)
    lines = [f"# {format_value(str(title))}", ""]
    for name, section in doc.items():
        heading = format_value(name.replace("_", " ").capitalize())
        lines += [f"## {heading}", "", *section_markdown(section), ""]
    return "\n".join(lines)


def write_report(directory: str | os.PathLike[str], report: Mapping[str, Any]
                 ) -> tuple[Path, Path]:
    """Write ``report.json`` (every value, numpy converted) and ``report.md`` (tables).

    Typical top-level sections: ``inputs``, ``solver``, ``timings``, ``energies``,
    ``probes``; any mapping of JSON-able values works (see :func:`section_markdown`).
    """
    folder = _require_folder(directory)
    if not isinstance(report, Mapping):
        raise InputError(f"report must be a mapping of section name to content, got "
                         f"{type(report).__name__}")
    doc = plain(report)
    json_path = write_text(folder / "report.json", json.dumps(doc, indent=2) + "\n")
    md_path = write_text(folder / "report.md", report_markdown(doc))
    return json_path, md_path
