"""Reading a foreign CAD file in a child process, so that a crash of the reader is an error.

openNURBS (rhino3dm) and OpenCASCADE are native libraries: some malformed files (an IGES
B-spline surface with a negative pole count, for one) end the process with a segmentation
fault before any check of ours can run. :func:`read_in_child` runs a reader in a child
interpreter (``python -c``, started once per process and kept for later reads, so that
OpenCASCADE is imported once) and receives its result as a pickle of plain numpy arrays
and strings. The reader's ``InputError`` and warnings are raised and re-issued here; the
child's death becomes an ``InputError`` naming the file, and the next read starts a
fresh child. The child is started with ``subprocess``, not ``multiprocessing``, so that
the caller's main script is never run again in it.
"""

from __future__ import annotations

import atexit
import importlib
import os
import pickle
import signal
import subprocess
import sys
import tempfile
import threading
import traceback
import warnings
from pathlib import Path
from typing import Any, Callable

from .errors import InputError, InputWarning

#: the child: the caller's import path first (as ``multiprocessing`` does); the package
#: as a bare namespace (its ``__init__``, which imports the whole library, is not run:
#: the readers' modules import only numpy, the CAD library and each other); then serve
_CHILD = """
import importlib.util, pickle, sys, types
sys.path[:0] = pickle.load(sys.stdin.buffer)
package = types.ModuleType("splinedeform")
package.__path__ = list(importlib.util.find_spec("splinedeform").submodule_search_locations)
sys.modules["splinedeform"] = package
from splinedeform.cad_child import serve
serve()
"""


class _Child:
    """One reader process and the lock that makes its requests one at a time."""

    def __init__(self) -> None:
        self.process: subprocess.Popen[bytes] | None = None
        self.owner = 0                      # the process that started it (not a fork of it)
        self.errors: Any = None             # the child's stderr, a temporary file
        self.lock = threading.Lock()

    def request(self, message: tuple[Any, ...]) -> tuple[str, Any, list[str]]:
        """Send ``message``; the child's answer, or EOFError(exit code, last line of its
        stderr) if it died."""
        if self.process is None or self.process.poll() is not None or \
                self.owner != os.getpid():
            self.errors = tempfile.TemporaryFile()
            self.process = subprocess.Popen(
                [sys.executable, "-c", _CHILD], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                stderr=self.errors)
            self.owner = os.getpid()
            pickle.dump(list(sys.path), self.process.stdin)
        assert self.process.stdin is not None and self.process.stdout is not None
        try:
            pickle.dump(message, self.process.stdin)
            self.process.stdin.flush()
            return pickle.load(self.process.stdout)
        except (EOFError, OSError, pickle.UnpicklingError):
            code = self.process.wait()
            self.process = None
            self.errors.seek(0)
            lines = self.errors.read().decode("utf-8", "replace").strip().splitlines()
            raise EOFError(code, lines[-1] if lines else "") from None

    def close(self) -> None:
        if self.process is not None and self.process.poll() is None:
            self.process.stdin.close()          # type: ignore[union-attr]  (EOF: it returns)
            try:
                self.process.wait(timeout=5)
            except subprocess.TimeoutExpired:   # pragma: no cover - a stuck reader
                self.process.kill()
        self.process = None


_child = _Child()
atexit.register(_child.close)


def read_in_child(reader: Callable[..., dict[str, Any]], path: Path, *args: Any,
                  library: str = "the CAD reader") -> dict[str, Any]:
    """``reader(path, *args)`` run in the reader child process; its result.

    ``reader`` is a module-level function (the child imports it by name). Its
    :class:`~splinedeform.errors.InputError` is raised again here with the same message,
    its warnings are issued again here (as :class:`~splinedeform.errors.InputWarning`),
    and any other exception or the death of the child (a signal, an exit) raises an
    ``InputError`` that names ``path`` and ``library``.
    """
    with _child.lock:
        try:
            outcome, payload, messages = _child.request(
                (reader.__module__, reader.__qualname__, os.getcwd(), path, args))
        except EOFError as exc:
            code, last = exc.args
            if code is not None and code > 0:      # Python failed in the child, not the file
                raise InputError(f"{path}: the reader process for {library} failed "
                                 f"({_exit_description(code)}: {last or 'no message'})"
                                 ) from None
            raise InputError(f"{path}: {library} crashed reading this file "
                             f"({_exit_description(code)}); the file is probably "
                             "malformed (damaged or written by a faulty exporter)") from None
    for message in messages:
        warnings.warn(message, InputWarning, stacklevel=3)
    if outcome == "error":
        raise InputError(payload)
    return payload


def serve() -> None:
    """The child's loop: read a request from stdin, answer on the original stdout.

    File descriptor 1 is pointed at the null device first: the native libraries print
    (OpenCASCADE its statistics) on it, which would corrupt the answers.
    """
    answers = os.fdopen(os.dup(1), "wb")
    os.dup2(os.open(os.devnull, os.O_WRONLY), 1)
    requests = sys.stdin.buffer
    while True:
        try:
            module, name, folder, path, args = pickle.load(requests)
        except EOFError:
            return
        os.chdir(folder)                 # relative paths as the caller sees them
        reader = getattr(importlib.import_module(module), name)
        pickle.dump(_answer(reader, path, *args), answers)
        answers.flush()


def _answer(reader: Callable[..., dict[str, Any]], path: Path,
            *args: Any) -> tuple[str, Any, list[str]]:
    """``(outcome, payload, warning messages)`` of ``reader(path, *args)``."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            outcome, payload = "ok", reader(path, *args)
        except InputError as exc:
            outcome, payload = "error", str(exc)
        except Exception as exc:  # noqa: BLE001  (a library failure: named, not a traceback)
            last = traceback.extract_tb(exc.__traceback__)[-1]
            outcome, payload = "error", (f"{path}: the reader failed on this file "
                                         f"({type(exc).__name__}: {exc} in {last.name}); "
                                         "the file is probably malformed")
    return outcome, payload, [str(w.message) for w in caught]


def _exit_description(code: int | None) -> str:
    """``signal SIGSEGV`` for a negative exit code, ``exit code 3`` otherwise."""
    if code is not None and code < 0:
        try:
            return f"signal {signal.Signals(-code).name}"
        except ValueError:
            return f"signal {-code}"
    return f"exit code {code}"
