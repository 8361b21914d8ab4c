"""A run owns its outputs in a folder: a manifest, stale files of earlier runs, temporaries.

Each run of a scenario ``<name>`` keeps ``<name>.manifest.json`` in its output folder:

``{"format": "splinedeform-run-manifest", "version": 1, "scenario": <name>,
"complete": bool, "files": [{"name", "bytes", "sha256"}, ...], "removed": [...]}``

The protocol (:func:`claim_folder`):

1. take an exclusive lock on the folder (``flock`` on the directory; a second run into
   the same folder is refused while the first one lives; the lock dies with the process);
2. read the earlier manifest of ``<name>`` (if any): the files that run wrote;
3. write a manifest with ``"complete": false`` that claims the files this run will write
   (except files already there that no earlier run recorded: never ours to delete) and
   the earlier files not yet removed, so a run killed at any moment leaves a record;
4. remove the earlier run's files that this run will not write again — only when their
   size and SHA-256 still match the manifest (or the manifest was incomplete, so no
   content was recorded), and never a file another scenario's manifest in the folder
   lists; remove our own hidden temporaries ``.<stem>.<12 hex>.tmp<suffix>`` of every
   file an earlier run or this run writes (left by a killed run);
5. the run writes its outputs (each atomically), then :meth:`FolderClaim.finish` writes
   the manifest with ``"complete": true`` and every file's size and SHA-256, last and
   atomically. A set without a complete manifest, or whose files do not match it, was
   interrupted or changed.

Files that look like ours (``<name>_0000.vtu`` …) but that no manifest records are left
in place and reported (:attr:`FolderClaim.kept`).
"""

from __future__ import annotations

import hashlib
import json
import os
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..errors import InputError
from .atomic import _check_stem, write_text

MANIFEST_FORMAT = "splinedeform-run-manifest"
MANIFEST_VERSION = 1
_TEMPORARY = re.compile(r"^\.(?P<stem>.+)\.[0-9a-f]{12}\.tmp(?P<suffix>\.[^.]*)?$")


def manifest_name(stem: str) -> str:
    """``<stem>.manifest.json``."""
    return f"{stem}.manifest.json"


def file_digest(path: Path) -> tuple[int, str]:
    """Size in bytes and SHA-256 (hex) of a file, read in 1 MiB blocks."""
    digest = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            digest.update(block)
    return path.stat().st_size, digest.hexdigest()


def read_manifest(path: Path) -> dict[str, Any] | None:
    """The manifest at ``path``, None if absent; a file that is not one is refused."""
    if not path.exists():
        return None
    try:
        doc = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise InputError(f"{path} is not a splinedeform run manifest ({exc}); move it away "
                         f"or choose another output folder") from None
    files = doc.get("files") if isinstance(doc, dict) else None
    if not isinstance(doc, dict) or doc.get("format") != MANIFEST_FORMAT \
            or not isinstance(files, list) \
            or not all(isinstance(f, dict) and isinstance(f.get("name"), str) for f in files):
        raise InputError(f"{path} is not a splinedeform run manifest (format "
                         f"{MANIFEST_FORMAT!r} with a list of files); move it away or choose "
                         f"another output folder")
    return doc


def _entries(doc: dict[str, Any] | None) -> dict[str, dict[str, Any]]:
    """File name → entry, for plain names only (a manifest never points outside its folder)."""
    if doc is None:
        return {}
    return {f["name"]: f for f in doc["files"]
            if f["name"] and "/" not in f["name"] and "\\" not in f["name"]
            and f["name"] not in (".", "..")}


@dataclass
class FolderClaim:
    """What :func:`claim_folder` found and did; :meth:`finish` records the run's files."""

    folder: Path
    stem: str
    planned: list[str]
    removed: list[Path] = field(default_factory=list)
    kept: list[tuple[Path, str]] = field(default_factory=list)
    manifest: Path | None = None
    _lock: int | None = None

    def finish(self) -> Path:
        """Write the complete manifest (size and SHA-256 of every planned file), atomically.

        Called after the run wrote all its files; a planned file that is missing is an
        error of the caller (``RuntimeError``), not of the input.
        """
        missing = [name for name in self.planned if not (self.folder / name).is_file()]
        if missing:
            raise RuntimeError(f"the run did not write {', '.join(missing)} into {self.folder}")
        files = []
        for path in (self.folder / name for name in self.planned):
            size, sha = file_digest(path)
            files.append({"name": path.name, "bytes": size, "sha256": sha})
        doc = {"format": MANIFEST_FORMAT, "version": MANIFEST_VERSION, "scenario": self.stem,
               "complete": True, "files": files,
               "removed": [p.name for p in self.removed]}
        self.manifest = write_text(self.folder / manifest_name(self.stem),
                                   json.dumps(doc, indent=1) + "\n")
        return self.manifest

    def release(self) -> None:
        """Drop the folder lock (also dropped when the process ends)."""
        if self._lock is not None:
            os.close(self._lock)
            self._lock = None


def incomplete_note(folder: str | os.PathLike[str], stem: str) -> str | None:
    """What an interrupted run of ``stem`` left in ``folder``, in words; None if nothing.

    Reads ``<stem>.manifest.json``: when it says ``"complete": false``, the note names it
    and counts the listed files present (whole: every file is written atomically) and
    missing. A complete manifest, or none, means the folder holds no unfinished set.
    """
    root = Path(folder)
    path = root / manifest_name(stem)
    try:
        doc = read_manifest(path)
    except InputError:
        return None
    if doc is None or doc.get("complete") is not False:
        return None
    names = list(_entries(doc))
    missing = [name for name in names if not (root / name).is_file()]
    shown = ", ".join(missing[:3]) + (f" and {len(missing) - 3} more" if len(missing) > 3
                                       else "")
    return (f"{path} is marked incomplete ({len(names) - len(missing)} of {len(names)} "
            f"files there" + (f"; missing {shown}" if missing else "") + ")")


def _lock_folder(folder: Path) -> int | None:
    try:
        import fcntl
    except ImportError:          # pragma: no cover - not on POSIX: no lock
        return None
    fd = os.open(folder, os.O_RDONLY)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:
        os.close(fd)
        raise InputError(f"another splinedeform run is writing into {folder}; wait for it "
                         f"or choose another output folder") from None
    return fd


def _claimed_by_others(folder: Path, stem: str) -> set[str]:
    names: set[str] = set()
    for path in folder.glob("*.manifest.json"):
        if path.name != manifest_name(stem):
            try:
                names |= set(_entries(read_manifest(path)))
            except InputError:
                continue                      # not ours to judge; it claims nothing
    return names


def claim_folder(folder: str | os.PathLike[str], stem: str, planned: list[str],
                 frame_pattern: str | None = None) -> FolderClaim:
    """Lock ``folder`` for a run of ``stem`` that will write ``planned``; clean what is ours.

    Parameters
    ----------
    folder : path-like
        The output folder (exists).
    stem : str
        The scenario name; the manifest is ``<stem>.manifest.json``.
    planned : list of str
        Names of every file this run will write.
    frame_pattern : str, optional
        A regular expression of per-frame file names (e.g. ``<stem>_\\d{4,}\\.vtu``):
        matching files that no manifest records are reported in :attr:`FolderClaim.kept`.

    Returns
    -------
    FolderClaim
        With the files removed and the files kept (and why). Call
        :meth:`FolderClaim.finish` after writing and :meth:`FolderClaim.release` at the end.
    """
    root = Path(folder)
    _check_stem(stem)
    claim = FolderClaim(root, stem, list(planned), _lock=_lock_folder(root))
    try:
        _clean(claim, frame_pattern)
    except BaseException:
        claim.release()
        raise
    return claim


def _clean(claim: FolderClaim, frame_pattern: str | None) -> None:
    root, stem = claim.folder, claim.stem
    earlier = _entries(read_manifest(root / manifest_name(stem)))
    planned = set(claim.planned)
    foreign = {name for name in planned if name not in earlier and (root / name).exists()}
    stale = {name: entry for name, entry in earlier.items() if name not in planned}
    # 3. record before touching anything: this run's files and the stale ones still there
    files = [{"name": name, "bytes": None, "sha256": None}
             for name in claim.planned if name not in foreign]
    files += [{"name": name, "bytes": entry.get("bytes"), "sha256": entry.get("sha256")}
              for name, entry in stale.items() if (root / name).exists()]
    write_text(root / manifest_name(stem),
               json.dumps({"format": MANIFEST_FORMAT, "version": MANIFEST_VERSION,
                           "scenario": stem, "complete": False, "files": files},
                          indent=1) + "\n")
    # 4. stale files of the earlier run
    others = _claimed_by_others(root, stem)
    for name, entry in sorted(stale.items()):
        path = root / name
        if not path.is_file() or path.is_symlink():
            continue
        if name in others:
            claim.kept.append((path, "another scenario's manifest lists it"))
            continue
        if entry.get("sha256") is not None and \
                file_digest(path) != (entry.get("bytes"), entry.get("sha256")):
            claim.kept.append((path, "changed since an earlier run wrote it"))
            continue
        path.unlink()
        claim.removed.append(path)
    # our temporaries, left by a killed run
    ours = set(earlier) | planned | {manifest_name(stem)}
    for path in sorted(root.iterdir()):
        match = _TEMPORARY.match(path.name)
        if match and match["stem"] + (match["suffix"] or "") in ours and path.is_file() \
                and not path.is_symlink():
            path.unlink()
            claim.removed.append(path)
    if frame_pattern is not None:
        pattern = re.compile(frame_pattern)
        for path in sorted(root.iterdir()):
            if pattern.fullmatch(path.name) and path.name not in planned \
                    and path.name not in earlier:
                claim.kept.append((path, "looks like an output but no run recorded it; "
                                         "not removed"))
