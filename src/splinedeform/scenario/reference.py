"""The key reference of ``docs/scenario.md``, written from the models of :mod:`.schema`.

Each table of the reference sits between ``<!-- keys: NAME -->`` and ``<!-- /keys -->``
in the document; :func:`update` rewrites them, and a test fails when the document differs
from what the models say. Regenerate after changing a key::

    python -m splinedeform.scenario.reference docs/scenario.md
"""

from __future__ import annotations

import math
import re
import sys
from pathlib import Path
from typing import Any

from ..input_files import read_input_text
from .checks import Key
from .keys import (BOUNDARY_KEYS, FREE_REGION_KEYS, LOAD_KEYS, MATERIAL_KEYS, OUTPUT_KEYS,
                   SHAPE_PARAMETERS, SOLVE_KEYS, SURFACE_KEYS, TOP_KEYS)

HEADER = "| key | type | default | meaning |\n|---|---|---|---|\n"
_BLOCK = re.compile(r"(<!-- keys: (\w+) -->\n)(.*?)(<!-- /keys -->)", re.S)


def _value(value: Any) -> str:
    if isinstance(value, str):
        return f'"{value}"'
    if isinstance(value, float) and math.isinf(value):
        return "inf"
    if isinstance(value, tuple):
        return "[" + ", ".join(_value(v) for v in value) + "]"
    return repr(value)


def _default(key: Key) -> str:
    if key.shown_default is not None:
        return key.shown_default
    if key.required:
        return "required"
    return "none" if key.default is None else f"`{_value(key.default)}`"


def _cell(text: str) -> str:
    return text.replace("|", "\\|")


def _rows(prefix: str, keys: dict[str, Key]) -> str:
    return "".join(f"| `{prefix}{name}` | {_cell(key.allowed)} | {_cell(_default(key))} | "
                   f"{_cell(key.doc)} |\n" for name, key in keys.items())


def _shape_rows() -> str:
    """One row per shape parameter; a parameter shared by shapes says which shape means what."""
    names: dict[str, list[tuple[str, Key]]] = {}
    for shape, params in SHAPE_PARAMETERS.items():
        for name, key in params.items():
            names.setdefault(name, []).append((shape, key))
    rows = []
    for name, uses in names.items():
        types = list(dict.fromkeys(key.allowed for _, key in uses))
        if len(types) > 1:
            types = [", ".join(f"{key.allowed} ({shape})" for shape, key in uses)]
        defaults = list(dict.fromkeys(_default(key) for _, key in uses))
        default = defaults[0] if len(defaults) == 1 else ", ".join(
            f"{_default(key)} ({shape})" for shape, key in uses)
        meanings: dict[str, list[str]] = {}
        for shape, key in uses:
            meanings.setdefault(key.doc, []).append(f"`{shape}`")
        meaning = "; ".join(f"{', '.join(shapes)}: {doc}" for doc, shapes in meanings.items())
        rows.append(f"| `surface.{name}` | {_cell(types[0])} | {_cell(default)} | "
                    f"{_cell(meaning)} |\n")
    return "".join(rows)


def tables() -> dict[str, str]:
    """Markdown table of each reference block, by block name."""
    return {
        "top": HEADER + _rows("", TOP_KEYS),
        "surface": HEADER + _rows("surface.", SURFACE_KEYS),
        "shapes": HEADER + _shape_rows(),
        "material": HEADER + _rows("material.", MATERIAL_KEYS),
        "boundary": HEADER + _rows("boundary.", BOUNDARY_KEYS)
        + _rows("boundary.free_region.", FREE_REGION_KEYS),
        "load": HEADER + _rows("load.", LOAD_KEYS),
        "solve": HEADER + _rows("solve.", SOLVE_KEYS),
        "output": HEADER + _rows("output.", OUTPUT_KEYS),
    }


def update(text: str) -> str:
    """``text`` with every ``<!-- keys: NAME -->`` block replaced by its generated table."""
    generated = tables()

    def fill(match: re.Match) -> str:
        name = match.group(2)
        if name not in generated:
            raise KeyError(f"unknown key reference block {name!r}; known: {sorted(generated)}")
        return match.group(1) + generated[name] + match.group(4)
    return _BLOCK.sub(fill, text)


def blocks(text: str) -> list[str]:
    """Names of the reference blocks present in ``text``."""
    return [m.group(2) for m in _BLOCK.finditer(text)]


def main(argv: list[str] | None = None) -> int:
    """Rewrite the reference blocks of the given Markdown files in place (each written
    whole or not at all); a file that cannot be read is named on stderr, exit code 2."""
    from ..errors import InputError
    from ..export.atomic import write_text

    for name in (argv if argv is not None else sys.argv[1:]) or ["docs/scenario.md"]:
        path = Path(name)
        try:
            write_text(path, update(read_input_text(path, "Markdown file")))
        except InputError as error:
            print(f"error: {error}", file=sys.stderr)
            return 2
        print(f"wrote the key reference of {path}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
