"""Atomic writing: every output file appears whole under its final name or not at all.

The content goes to a hidden temporary file ``.<stem>.<12 hex>.tmp<suffix>`` in the
target folder, which then replaces the target with :func:`os.replace` (an atomic rename
on one file system). A failure part-way leaves the previous target (or none) and no
temporary file behind; a killed process may leave the temporary file, which the next run
into that folder removes (:mod:`splinedeform.export.run_folder`).
"""

from __future__ import annotations

import os
import uuid
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path

from ..errors import InputError

@contextmanager
def atomic_path(path: str | os.PathLike[str]) -> Iterator[Path]:
    """Yield a temporary path beside ``path`` (same suffix); on success it replaces ``path``.

    The temporary file (a fresh hidden name, created by the caller's writer, so it gets
    the usual permissions) lives in the target folder so :func:`os.replace` is an atomic
    rename. If the body raises, the temporary file is removed and ``path`` is untouched.
    """
    target = Path(path)
    if not target.parent.is_dir():
        raise InputError(f"cannot write {target}: folder {target.parent} does not exist")
    tmp = target.parent / f".{target.stem}.{uuid.uuid4().hex[:12]}.tmp{target.suffix}"
    try:
        yield tmp
        os.replace(tmp, target)
    finally:
        if tmp.exists():
            tmp.unlink()


def write_text(path: str | os.PathLike[str], text: str) -> Path:
    """Write ``text`` (UTF-8) to ``path`` atomically."""
    with atomic_path(path) as tmp:
        tmp.write_text(text, encoding="utf-8")
    return Path(path)


def write_with(path: str | os.PathLike[str], writer: Callable[[Path], object]) -> Path:
    """Call ``writer(tmp)`` on a temporary path and move the result to ``path`` atomically."""
    with atomic_path(path) as tmp:
        writer(tmp)
    return Path(path)


def _require_folder(directory: str | os.PathLike[str]) -> Path:
    folder = Path(directory)
    if not folder.is_dir():
        raise InputError(f"output folder {folder} does not exist (create it first)")
    return folder


def _check_stem(stem: str) -> str:
    if not isinstance(stem, str) or not stem or any(c in stem for c in "/\\\0"):
        raise InputError(f"file stem must be a non-empty name without path separators, "
                         f"got {stem!r}")
    return stem

