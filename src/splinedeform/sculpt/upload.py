"""A surface loaded from the page: a ``.3dm`` file, a control-net file or a scenario.

The page sends the file's bytes (``POST /api/load``, at most :data:`MAX_UPLOAD` bytes) and
its name, which says only what kind of file it is (the suffix) and how errors name it: the
server writes the bytes under a name of its own beside the save file
(``<save stem>-loaded-<version><suffix>``), so that Save can name it, and never opens a
path that a message names.

- ``.3dm`` (openNURBS; STEP and IGES too where OpenCASCADE is installed) or ``.json`` (the
  project's net file): the surface of the current scenario becomes ``shape = "cad"`` or
  ``"file"`` on that file (its first surface); material and boundary stay.
- ``.toml``: a whole scenario (surface, material, boundary); a path it names is read from
  the save file's folder and must lie inside it.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from ..errors import InputError, ScenarioError
from ..export.atomic import write_with
from ..scenario import parse_scenario, with_overrides
from ..scenario.spec import Scenario

MAX_UPLOAD = 16 * 2**20
"""Largest file the page may load, in bytes (a 200 × 200 net as JSON is about 2 MB)."""

#: suffix -> what it is, in words
LOADABLE = {".3dm": "a Rhino .3dm file", ".stp": "STEP", ".step": "STEP", ".igs": "IGES",
            ".iges": "IGES", ".json": "a control-net file", ".toml": "a scenario"}
CAD = (".3dm", ".stp", ".step", ".igs", ".iges")


def loadable(name: str) -> str:
    """The suffix of ``name`` if the page may load it, else an :class:`InputError`."""
    suffix = Path(name).suffix.lower()
    if suffix not in LOADABLE:
        offered = ", ".join(f"{s} ({w})" for s, w in LOADABLE.items())
        raise InputError(f"{name}: cannot load this kind of file; the page loads {offered}")
    return suffix


def uploaded_scenario(current: Scenario, name: str, content: bytes, folder: Path, stem: str
                      ) -> tuple[Scenario, Path | None]:
    """The scenario the file ``name`` (bytes ``content``) makes, and where the surface file
    was written (None for a scenario: nothing is written)."""
    suffix = loadable(name)
    if not content:
        raise InputError(f"{name}: the file is empty")
    if len(content) > MAX_UPLOAD:
        raise InputError(f"{name}: {len(content)} bytes, more than the {MAX_UPLOAD} the page may load")
    if suffix == ".toml":
        try:
            text = content.decode("utf-8")
        except UnicodeDecodeError as exc:
            raise InputError(f"{name}: not UTF-8 text (byte {exc.start}); a scenario is TOML") from None
        return parse_scenario(text, source=name, directory=folder.resolve()), None
    path = write_with(folder / f"{stem}{suffix}", lambda tmp: tmp.write_bytes(content))
    moved = dataclasses.replace(current, directory=folder.resolve())
    table: dict[str, Any] = {"shape": "cad" if suffix in CAD else "file", "path": path.name}
    return with_overrides(moved, {"surface": table}, origin=f"loaded {name}"), path


@contextmanager
def loaded(current: Scenario, name: str, content: bytes, folder: Path, stem: str
           ) -> Iterator[Scenario]:
    """:func:`uploaded_scenario` for the ``with`` block that solves it: if the block (or the
    reading) fails, the file written is removed and the error names the file as the page
    did (``name``), not the server's copy."""
    path: Path | None = None
    try:
        scenario, path = uploaded_scenario(current, name, content, folder, stem)
        yield scenario
    except (InputError, ScenarioError) as exc:
        if path is not None:
            path.unlink(missing_ok=True)
        text = str(exc)
        if path is not None:
            text = text.replace(str(path.resolve()), name).replace(str(path), name)
        raise InputError(text) from None
    except Exception:
        if path is not None:
            path.unlink(missing_ok=True)
        raise
