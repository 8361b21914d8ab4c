"""Where the cases run: a Dask ``LocalCluster`` of worker processes, or a scheduler's address.

A local cluster listens on the loopback address only (``127.0.0.1``), one worker process
per core by default, one thread each (the workers' BLAS threads are limited to one by
Dask's nanny), each with a memory limit (``"2GiB"``; Dask's default is the machine's memory
shared among the workers).

A local cluster's fixed cost is kept off the cases' path:

- its workers import the task code as they start (Dask's worker ``preload`` of
  :data:`PRELOAD`), not on their first task, and they start in the background: the
  client is returned once the scheduler is up, so the caller submits while the workers
  start;
- :func:`close_in_background` stops the cluster (its nannies wait for their worker
  processes to exit) while the caller writes its results.
"""

from __future__ import annotations

import os
import threading
from pathlib import Path
from contextlib import ExitStack, contextmanager
from typing import Any, Callable, Iterator

from ..errors import InputError

#: the module a sweep's tasks run, imported by each local worker as it starts
PRELOAD = "splinedeform.study.solve"


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
        # no worker yet: the client connects to the scheduler at once, the workers are
        # started by scale() below while the caller goes on
        cluster = LocalCluster(n_workers=0, threads_per_worker=1, processes=True,
                               host="127.0.0.1", dashboard_address="127.0.0.1:0",
                               memory_limit=memory_limit if memory_limit is not None
                               else "auto", preload=[PRELOAD])
    except (ValueError, TypeError) as exc:
        raise InputError(f"cannot start the local Dask cluster ({exc}); --memory-limit "
                         "takes a size such as 2GiB") from None
    try:
        # not ``with Client(...)``: its context is entered and left in one thread, and
        # close_in_background closes the client in another
        client = Client(cluster)
        try:
            cluster.scale(n)
            yield client
        finally:
            client.close()
    finally:
        cluster.close()


def _requested(client: Any) -> set | None:
    """The workers a local cluster of ``client`` has or is starting, or None."""
    return getattr(getattr(client, "cluster", None), "requested", None)


def expected_workers(client: Any) -> int:
    """The workers a client's cluster has or is starting (a local cluster's requested
    count, else those connected to the scheduler; at least 1)."""
    requested = _requested(client)
    if requested:
        return len(requested)
    return max(1, len(client.scheduler_info().get("workers", {})))


def spare_core(client: Any) -> bool:
    """Whether this machine has a core that the cluster's workers here leave idle (a local
    cluster's requested workers, else the threads of the workers on the loopback address)."""
    requested = _requested(client)
    if requested is not None:
        here = len(requested)
    else:
        workers = client.scheduler_info().get("workers", {})
        here = sum(int(w.get("nthreads", 1)) for address, w in workers.items()
                   if "127.0.0.1" in address or "localhost" in address)
    return here < (os.cpu_count() or 1)


def close_in_background(stack: ExitStack) -> Callable[[], None]:
    """Close ``stack`` (a cluster and its client) in a thread; returns the function that
    waits for it and raises what the close raised."""
    raised: list[BaseException] = []

    def close() -> None:
        try:
            stack.close()
        except BaseException as exc:  # noqa: BLE001  (raised again by join)
            raised.append(exc)

    thread = threading.Thread(target=close, name="splinedeform-cluster-close", daemon=True)
    thread.start()

    def join() -> None:
        thread.join()
        if raised:
            raise raised[0]

    return join


def dashboard(client: Any) -> str | None:
    """The address of the Dask dashboard, or None when it does not run (needs bokeh)."""
    try:
        return str(client.dashboard_link) if "dashboard" in client.scheduler_info().get(
            "services", {}) else None
    except Exception:  # noqa: BLE001  (no dashboard is no error)
        return None
