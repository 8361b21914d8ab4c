"""Opening the files a scenario names: regular files only, sizes known before reading.

Every input file (the scenario, ``surface.path``, control nets, point grids) is opened by
:func:`open_input`, which refuses what is not a regular file (a named pipe without a
writer would block the reader forever, a device never ends) without blocking on it, and a
file larger than the reader's cap. The sizes an array file declares are checked before
anything is allocated (:func:`check_array_file`): a ``.npy`` header's ``shape × itemsize``
and, in a ``.npz``, every member's declared size and header, against
:data:`MAX_ARRAY_BYTES` (the default memory budget); JSON nested deeper than the parser's
recursion is refused naming the file (:func:`load_json`).
"""

from __future__ import annotations

import json
import math
import os
import stat
import zipfile
from pathlib import Path
from typing import IO, Any

from .budget import Budget
from .errors import InputError

#: largest array a file may declare (bytes): the default memory budget of a run
MAX_ARRAY_BYTES = Budget().memory
#: largest text file read whole (a scenario, a JSON control net): its parsed objects take
#: about 30 times the text's size
MAX_TEXT_BYTES = 128 * 2**20


def open_input(path: str | os.PathLike[str], what: str = "input file",
               max_bytes: float = math.inf) -> IO[bytes]:
    """``path`` opened for binary reading, refused unless it is a regular file.

    Opened without blocking (``O_NONBLOCK``, which a named pipe without a writer needs),
    checked with ``fstat`` on the open descriptor (no race with a replaced file), then
    switched back to blocking reads.

    Raises
    ------
    InputError
        Naming the file: not found, not a regular file (and what it is), larger than
        ``max_bytes``, or unreadable.
    """
    target = Path(path)
    try:
        fd = os.open(target, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0)
                     | getattr(os, "O_BINARY", 0))
    except FileNotFoundError:
        raise InputError(f"{target}: {what} not found") from None
    except OSError as exc:
        raise InputError(f"{target}: cannot open the {what} ({exc.strerror or exc})") from None
    try:
        info = os.fstat(fd)
        if not stat.S_ISREG(info.st_mode):
            raise InputError(f"{target}: the {what} is {_kind(info.st_mode)}, not a regular "
                             "file; give the path of a file")
        if info.st_size > max_bytes:
            raise InputError(f"{target}: the {what} has {info.st_size} bytes, more than the "
                             f"{max_bytes:.0f} read at most")
        if hasattr(os, "set_blocking"):
            os.set_blocking(fd, True)
        return os.fdopen(fd, "rb")
    except BaseException:
        os.close(fd)
        raise


def _kind(mode: int) -> str:
    for test, name in ((stat.S_ISDIR, "a folder"), (stat.S_ISFIFO, "a named pipe"),
                       (stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"),
                       (stat.S_ISSOCK, "a socket")):
        if test(mode):
            return name
    return "not a regular file"


def read_input_text(path: str | os.PathLike[str], what: str = "input file") -> str:
    """The UTF-8 text of a regular file of at most :data:`MAX_TEXT_BYTES`; a leading byte
    order mark is dropped."""
    with open_input(path, what, MAX_TEXT_BYTES) as fh:
        data = fh.read()
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise InputError(f"{path}: the {what} is not UTF-8 text ({exc})") from None


def load_json(path: str | os.PathLike[str], what: str = "JSON file") -> Any:
    """The parsed JSON of a regular file; syntax errors and nesting deeper than the
    parser's recursion are an InputError naming the file."""
    text = read_input_text(path, what)
    try:
        return json.loads(text)
    except RecursionError:
        raise InputError(f"{path}: arrays or objects nested too deep for a {what} (a control "
                         "net needs 4 levels)") from None
    except json.JSONDecodeError as exc:
        raise InputError(f"{path}: not a valid {what}: {exc}") from None


def check_array_file(fh: IO[bytes], path: str | os.PathLike[str],
                     max_bytes: float = MAX_ARRAY_BYTES) -> None:
    """Refuse a ``.npy`` / ``.npz`` whose declared arrays exceed ``max_bytes``, before
    ``numpy.load`` allocates them; ``fh`` is left at its start.

    ``.npy``: ``prod(shape) · itemsize`` from the header. ``.npz``: the sum over members of
    the larger of the member's declared uncompressed size (a zip member never inflates
    past it) and its ``.npy`` header's array size.
    """
    start = fh.tell()
    try:
        if zipfile.is_zipfile(fh):
            fh.seek(start)
            with zipfile.ZipFile(fh) as archive:
                total = 0
                for member in archive.infolist():
                    with archive.open(member) as inner:
                        declared = _npy_bytes(inner, f"{path} member {member.filename!r}")
                    total += max(member.file_size, declared)
        else:
            fh.seek(start)
            total = _npy_bytes(fh, str(path))
    except (zipfile.BadZipFile, OSError, EOFError) as exc:
        raise InputError(f"{path}: not a valid .npy / .npz file ({exc})") from None
    finally:
        fh.seek(start)
    if total > max_bytes:
        raise InputError(f"{path}: its arrays would take {total / 2**30:.3g} GiB, more than "
                         f"the {max_bytes / 2**30:.3g} GiB an input array may take")


def _npy_bytes(fh: IO[bytes], where: str) -> int:
    """``prod(shape) · itemsize`` declared by the ``.npy`` header at the start of ``fh``."""
    import numpy as np

    fmt = np.lib.format
    try:
        version = fmt.read_magic(fh)
        if version == (1, 0):
            shape, _, dtype = fmt.read_array_header_1_0(fh)
        elif version == (2, 0):
            shape, _, dtype = fmt.read_array_header_2_0(fh)
        else:
            raise ValueError(f"unsupported .npy format version {version}")
    except ValueError as exc:
        raise InputError(f"{where}: not a valid .npy array ({exc})") from None
    return math.prod(int(s) for s in shape) * max(dtype.itemsize, 1)
