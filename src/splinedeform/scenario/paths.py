"""A file named in a scenario (``surface.path``): resolved against the scenario's folder, and
refused where no file can have that name or it lies outside the folder."""

from __future__ import annotations

from pathlib import Path

from .locate import _Problems


def inside(directory: Path, written: str, allow_outside: bool, problems: _Problems) -> Path:
    """``written`` resolved against the scenario's folder; outside it only if allowed.

    The message is the same whether or not the outside file exists, and names the path as
    written (never where a symbolic link points).
    """
    folder = directory.resolve()
    unusable = unusable_path(written)
    if unusable:
        problems.add("surface.path", unusable)
        return folder / "surface.path"     # never read: the problem stops the scenario
    try:
        path = (folder / written).resolve()
    except (OSError, ValueError, RuntimeError) as exc:  # a loop of links, …
        problems.add("surface.path", f"cannot be resolved: {exc}")
        return folder / "surface.path"
    if not allow_outside and not path.is_relative_to(folder):
        problems.add("surface.path", f"{written!r} lies outside the scenario's folder; files "
                                     "are read only from that folder and its subfolders "
                                     "unless outside paths are allowed (command line: "
                                     "--allow-outside-paths, Python: allow_outside_paths=True)")
    return path


#: longest file name, and path, accepted in a scenario (the usual file system limits)
NAME_MAX, PATH_MAX = 255, 4096


def unusable_path(written: str) -> str:
    """Why ``written`` cannot name a file (a NUL character, too long, empty), or ``""``."""
    if not written.strip():
        return "is empty; expected the name of a file"
    if "\x00" in written:
        return (f"contains a NUL character (at position {written.index(chr(0))}), which no "
                "file name can hold")
    longest = max(len(part.encode("utf-8", "surrogateescape")) for part in Path(written).parts)
    if longest > NAME_MAX or len(written.encode("utf-8", "surrogateescape")) > PATH_MAX:
        return (f"is too long ({len(written)} characters, longest part {longest} bytes); file "
                f"names hold at most {NAME_MAX} bytes, paths {PATH_MAX}")
    return ""
