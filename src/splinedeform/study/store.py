"""The results of a sweep on disk: one file per case as it completes, tables at the end.

Each case's result is written atomically to ``OUT/cases/<hash>.json`` by the worker that
computed it (:mod:`splinedeform.export.atomic`): a case is either stored whole or not at
all, so a sweep killed at any moment and run again computes only the cases missing.
:func:`write_tables` assembles the rows into ``results.parquet`` and ``results.csv``.
"""

from __future__ import annotations

import csv
import io
import json
import math
from pathlib import Path
from typing import Any, Iterable

from ..export.atomic import write_text, write_with

CASES = "cases"


def case_file(folder: str | Path, digest: str) -> Path:
    """Where the result of the case with content hash ``digest`` is stored."""
    return Path(folder) / CASES / f"{digest}.json"


def stored_cases(folder: str | Path) -> list[Path]:
    """The case result files in ``folder`` (not the temporary files of writes under way)."""
    return [p for p in (Path(folder) / CASES).glob("*.json") if not p.name.startswith(".")]


def remove_partial(folder: str | Path) -> None:
    """Remove the temporary files a killed worker left mid-write (never a stored result)."""
    for path in (Path(folder) / CASES).glob(".*.tmp.json"):
        path.unlink(missing_ok=True)


def stored(folder: str | Path, digest: str) -> dict[str, Any] | None:
    """The stored result of a case, or None when it has none (or an unreadable one)."""
    try:
        return json.loads(case_file(folder, digest).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None


def store(folder: str | Path, digest: str, row: dict[str, Any]) -> Path:
    """Write a case's result atomically."""
    path = case_file(folder, digest)
    path.parent.mkdir(parents=True, exist_ok=True)
    return write_text(path, json.dumps(row, allow_nan=True, default=float) + "\n")


def flat(row: dict[str, Any]) -> dict[str, Any]:
    """A result row with its axis values as columns; a list value as one column per element
    (``load[1].at[1]``, ``load[1].at[2]``)."""
    out: dict[str, Any] = {"case": row["case"]}
    for key, value in row.get("values", {}).items():
        out.update(_elements(key, value))
    out.update({k: v for k, v in row.items() if k not in ("case", "values")})
    return out


def _elements(key: str, value: Any) -> dict[str, Any]:
    if isinstance(value, (list, tuple)):
        out: dict[str, Any] = {}
        for i, v in enumerate(value, start=1):
            out.update(_elements(f"{key}[{i}]", v))
        return out
    return {key: value}


def columns(rows: Iterable[dict[str, Any]]) -> list[str]:
    """The union of the rows' columns, in first-seen order."""
    names: dict[str, None] = {}
    for row in rows:
        names.update(dict.fromkeys(row))
    return list(names)


def write_tables(folder: str | Path, rows: list[dict[str, Any]]) -> tuple[Path, Path]:
    """``results.csv`` and ``results.parquet`` of the flat rows, written atomically."""
    folder = Path(folder)
    table = [flat(row) for row in rows]
    names = columns(table)
    text = io.StringIO()
    writer = csv.DictWriter(text, fieldnames=names, lineterminator="\n")
    writer.writeheader()
    for row in table:
        writer.writerow({k: _csv_value(row.get(k)) for k in names})
    csv_path = write_text(folder / "results.csv", text.getvalue())
    parquet_path = write_with(folder / "results.parquet", lambda tmp: _parquet(tmp, table, names))
    return csv_path, parquet_path


def _csv_value(value: Any) -> Any:
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return ""
    return repr(value) if isinstance(value, float) else value


def _parquet(path: Path, table: list[dict[str, Any]], names: list[str]) -> None:
    import pyarrow as pa
    import pyarrow.parquet as pq

    data = {}
    for name in names:
        column = [row.get(name) for row in table]
        kinds = {type(v) for v in column if v is not None}
        if kinds <= {int, float} and kinds != {int}:
            column = [math.nan if v is None else float(v) for v in column]
        elif not kinds <= {int} and not kinds <= {bool} and not kinds <= {str}:
            column = [None if v is None else str(v) for v in column]
        data[name] = pa.array(column)
    pq.write_table(pa.table(data), path)
