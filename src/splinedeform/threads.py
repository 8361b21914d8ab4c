"""How many BLAS threads the library's own hot calls use.

The dense and sparse kernels of a solve are small (SuperLU's supernodes, the ``eigh`` of a
Rayleigh–Ritz block, ``Φ Q`` per frame chunk) and a second BLAS thread rarely finds a free
core: on the two-core machine of the cost study, with one other busy process, two threads
made the same solve 2–18 times slower than one (benchmarks/results.md). So the library
runs its solves, eigen-solutions and frame evaluations with **one** BLAS thread unless told
otherwise:

* ``SPLINEDEFORM_THREADS=n`` (an integer ``n ≥ 1``) in the environment, or
  ``SPLINEDEFORM_THREADS=blas`` to leave the BLAS library's own setting alone;
* :func:`set_threads` from a program (``None``: back to the environment's setting).

The limit applies inside the library's calls only (threadpoolctl), so a program's own
numpy work keeps its threads. Without threadpoolctl the library runs with the BLAS setting.
"""

from __future__ import annotations

import functools
import os
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any, TypeVar

from .errors import InputError

ENVIRONMENT = "SPLINEDEFORM_THREADS"
DEFAULT = 1
"""BLAS threads of the library's hot calls when nothing is set."""
_chosen: list[int | str | None] = [None]
_depth = [0]
_controller: list[Any] = []
F = TypeVar("F", bound=Callable[..., Any])


def _parse(value: Any, where: str) -> int | str:
    if isinstance(value, str) and value.strip().lower() == "blas":
        return "blas"
    try:
        number = int(str(value).strip()) if isinstance(value, str) else value
    except ValueError:
        number = None
    if isinstance(number, bool) or not isinstance(number, int) or number < 1:
        raise InputError(f"{where} must be an integer >= 1 (BLAS threads of the library's "
                         f"solves) or 'blas' (leave BLAS's own setting), got {value!r}")
    return number


def set_threads(threads: int | str | None) -> None:
    """Set the BLAS threads of the library's calls: ``n ≥ 1``, ``"blas"`` (BLAS's own
    setting) or ``None`` (the ``SPLINEDEFORM_THREADS`` setting, else :data:`DEFAULT`)."""
    _chosen[0] = None if threads is None else _parse(threads, "threads")


def threads() -> int | str:
    """The BLAS threads the library's calls use now (an integer, or ``"blas"``)."""
    if _chosen[0] is not None:
        return _chosen[0]
    value = os.environ.get(ENVIRONMENT)
    if value is None or not value.strip():
        return DEFAULT
    return _parse(value, f"the environment variable {ENVIRONMENT}")


@contextmanager
def library_threads() -> Iterator[None]:
    """Run the enclosed block with :func:`threads` BLAS threads (nested blocks: once)."""
    setting = threads()
    if _depth[0] or setting == "blas":
        _depth[0] += 1
        try:
            yield
        finally:
            _depth[0] -= 1
        return
    try:
        from threadpoolctl import ThreadpoolController
    except ImportError:                 # pragma: no cover - threadpoolctl is a dependency
        yield
        return
    if not _controller:
        _controller.append(ThreadpoolController())
    _depth[0] += 1
    try:
        with _controller[0].limit(limits=setting, user_api="blas"):
            yield
    finally:
        _depth[0] -= 1


def owned(function: F) -> F:
    """Decorator: the call runs under :func:`library_threads`."""
    @functools.wraps(function)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        with library_threads():
            return function(*args, **kwargs)
    return wrapper  # type: ignore[return-value]
