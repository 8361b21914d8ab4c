"""Where the cases run: a Dask ``LocalCluster`` of worker processes, or a scheduler's address.

A local cluster listens on the loopback address only (``127.0.0.1``), one worker process
per core by default, one thread each (the workers' BLAS threads are limited to one by
Dask's nanny), each with a memory limit (``"2GiB"``; Dask's default is the machine's memory
shared among the workers).
"""

from __future__ import annotations

import os
from pathlib import Path
from contextlib import contextmanager
from typing import Any, Iterator

from ..errors import InputError


@contextmanager
def dask_client(workers: int | None = None, scheduler: str | None = None,
                memory_limit: str | None = None) -> Iterator[Any]:
    """A ``distributed.Client``: to ``scheduler`` when given, else to a new local cluster.

    ``scheduler`` is an address (``tcp://127.0.0.1:8786``) or the JSON file a scheduler
    started with ``--scheduler-file`` writes.

    Raises
    ------
    InputError
        When Dask is not installed (extra ``sweep``), ``workers < 1``, or the scheduler
        cannot be reached.
    """
    try:
        from distributed import Client, LocalCluster
    except ImportError:
        raise InputError("splinedeform sweep needs Dask distributed: pip install "
                         "'splinedeform[sweep]'") from None
    if scheduler is not None:
        if workers is not None or memory_limit is not None:
            raise InputError("--workers and --memory-limit apply to a local cluster; the "
                             "workers of --scheduler are started with their own options")
        try:
            if "://" not in scheduler and Path(scheduler).is_file():
                client = Client(scheduler_file=scheduler, timeout="10s")
            else:
                client = Client(scheduler, timeout="10s")
        except (OSError, TimeoutError, ValueError) as exc:
            raise InputError(f"cannot reach the Dask scheduler {scheduler!r}: {exc}") from None
        try:
            yield client
        finally:
            client.close()
        return
    n = workers if workers is not None else (os.cpu_count() or 1)
    if n < 1:
        raise InputError(f"--workers must be at least 1, got {n}")
    if memory_limit is not None:
        from dask.utils import parse_bytes

        try:
            parse_bytes(memory_limit)
        except (ValueError, TypeError):
            raise InputError(f"--memory-limit takes a size such as 2GiB or 500MB, got "
                             f"{memory_limit!r}") from None
    try:
        cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                               host="127.0.0.1", dashboard_address="127.0.0.1:0",
                               memory_limit=memory_limit if memory_limit is not None
                               else "auto")
    except (ValueError, TypeError) as exc:
        raise InputError(f"cannot start the local Dask cluster ({exc}); --memory-limit "
                         "takes a size such as 2GiB") from None
    try:
        with Client(cluster) as client:
            yield client
    finally:
        cluster.close()


def dashboard(client: Any) -> str | None:
    """The address of the Dask dashboard, or None when it does not run (needs bokeh)."""
    try:
        return str(client.dashboard_link) if "dashboard" in client.scheduler_info().get(
            "services", {}) else None
    except Exception:  # noqa: BLE001  (no dashboard is no error)
        return None
