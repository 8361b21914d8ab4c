"""Running a sweep: plan the cases, skip those stored, solve the rest on Dask, assemble.

``sweep(sweep_file, out)`` is the whole of ``splinedeform sweep``:

1. read and validate the sweep file and its base scenario (:mod:`.read`), plan the cases
   (:mod:`.cases`); a case whose values the scenario reader refuses gets its message;
2. read back the cases already stored in ``out/cases/`` (by content hash) — an
   interrupted sweep run again computes only what is missing;
3. group the remaining cases by model; a task solves one group, or several groups of few
   cases together (:func:`tasks`: about :data:`TASKS_PER_WORKER` tasks a worker, so that
   the scheduler's cost per task stays small beside the cases' work); Dask reschedules
   the task of a worker that dies, and the task skips the cases its first attempt stored;
4. write ``results.parquet``, ``results.csv`` and ``report.md`` (:mod:`.report`), while a
   local cluster started for the sweep stops (:func:`.cluster.close_in_background`).
"""

from __future__ import annotations

import time
import uuid
from contextlib import ExitStack
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

from ..errors import InputError
from .cases import Case, plan_cases
from .cluster import (close_in_background, dashboard, dask_client, expected_workers,
                      spare_core)
from .read import Sweep, load_sweep
from .solve import solve_groups
from .store import case_file, remove_partial, stored, write_tables

#: tasks a worker gets about, when the models are many and their cases few
TASKS_PER_WORKER = 8

#: ``progress(done, failed, running, total, dashboard)``, called about twice a second
SweepProgress = Callable[[int, int, int, int, "str | None"], None]


@dataclass
class SweepResult:
    """What a sweep produced: one row per case, in design order, and where it is."""

    sweep: Sweep
    folder: Path
    rows: list[dict[str, Any]]
    #: cases computed by this run, cases read back from ``folder``, models built
    computed: int = 0
    reused: int = 0
    models: int = 0
    wall_s: float = 0.0
    workers: int = 0
    dashboard: str | None = None
    files: dict[str, Path] = field(default_factory=dict)

    @property
    def failed(self) -> int:
        return sum(row["status"] != "ok" for row in self.rows)


def sweep(sweep_file_or_spec: str | Path | Sweep, out: str | Path, client: Any = None,
          workers: int | None = None, scheduler: str | None = None,
          memory_limit: str | None = None, progress: SweepProgress | None = None
          ) -> SweepResult:
    """Run every case of a sweep on Dask and write its tables and report to ``out``.

    Parameters
    ----------
    sweep_file_or_spec : path or Sweep
        A sweep file (``docs/sweep.md``) or one read by :func:`.read.load_sweep`.
    out : path
        Output folder, created if missing; cases already stored there are not run again.
    client : distributed.Client, optional
        Run on this client's cluster; else on ``scheduler`` (an address such as
        ``tcp://127.0.0.1:8786``), else on a new local cluster of ``workers`` processes
        (default one per core) with ``memory_limit`` each.
    progress : callable, optional
        ``progress(done, failed, running, total, dashboard)``.
    """
    start = time.perf_counter()
    spec = sweep_file_or_spec if isinstance(sweep_file_or_spec, Sweep) else \
        load_sweep(sweep_file_or_spec)
    folder = Path(out)
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise InputError(f"cannot create the output folder {folder}: {exc}") from None
    remove_partial(folder)
    cases = plan_cases(spec)
    pending = [c for c in cases
               if c.scenario is not None and not case_file(folder, c.hash).exists()]
    groups: dict[str, list[Case]] = {}
    for case in pending:
        groups.setdefault(case.model, []).append(case)
    result = SweepResult(sweep=spec, folder=folder, rows=[], computed=len(pending),
                         reused=sum(c.scenario is not None for c in cases) - len(pending),
                         models=len(groups))
    closed = lambda: None  # noqa: E731  (no cluster of our own to wait for)
    if groups:
        if client is not None:
            _run_groups(client, spec, folder, cases, list(groups.values()), progress, result)
        else:
            with ExitStack() as stack:
                own = stack.enter_context(dask_client(workers, scheduler, memory_limit))
                _run_groups(own, spec, folder, cases, list(groups.values()), progress, result)
                closed = close_in_background(stack.pop_all())
    try:
        result.rows = [_row(case, folder) for case in cases]
        from .report import write_report

        csv_path, parquet_path = write_tables(folder, result.rows)
        result.files = {"csv": csv_path, "parquet": parquet_path, **write_report(result)}
    finally:
        closed()
    result.wall_s = time.perf_counter() - start
    return result


def _row(case: Case, folder: Path) -> dict[str, Any]:
    if case.scenario is None:
        return {"case": case.index, "values": case.values, "status": case.error,
                "hash": case.hash, "model": case.model[:12]}
    row = stored(folder, case.hash)
    if row is None:     # the task's own rows are stored before it returns
        raise InputError(f"case {case.index}: its result {case_file(folder, case.hash)} is "
                         "missing or unreadable after the sweep")
    # a result is stored by content: a case equal to another (a value drawn twice), or one
    # computed by an earlier sweep at another place of its design, shares the result
    return {**row, "case": case.index, "values": case.values}


def tasks(groups: list[list[Case]], workers: int) -> list[list[list[Case]]]:
    """The groups packed into tasks in design order: consecutive groups join one task
    until it holds ``⌈cases / (TASKS_PER_WORKER · workers)⌉`` cases; a larger group is a
    task of its own."""
    size = -(-sum(len(g) for g in groups) // (TASKS_PER_WORKER * max(workers, 1)))
    packed: list[list[list[Case]]] = []
    for group in groups:
        if packed and sum(len(g) for g in packed[-1]) + len(group) <= size:
            packed[-1].append(group)
        else:
            packed.append([group])
    return packed


def _run_groups(client: Any, spec: Sweep, folder: Path, cases: list[Case],
                groups: list[list[Case]], progress: SweepProgress | None,
                result: SweepResult) -> None:
    """Submit the groups as tasks and wait, reporting progress; cancel on interrupt."""
    from distributed import wait

    run_id = uuid.uuid4().hex[:8]
    workers = expected_workers(client)
    futures = {client.submit(solve_groups, task, str(folder.resolve()), spec.cases_output,
                             key=f"splinedeform-sweep-{run_id}-{i}", pure=False):
               [case for group in task for case in group]
               for i, task in enumerate(tasks(groups, workers), start=1)}
    result.workers = workers
    result.dashboard = dashboard(client)
    if spare_core(client):      # else the imports would take a core from the workers
        from .report import import_writers_in_background

        import_writers_in_background()
    failed = sum(c.scenario is None for c in cases)
    try:
        remaining = set(futures)
        while remaining:
            try:
                wait(list(remaining), timeout=0.5, return_when="FIRST_COMPLETED")
            except TimeoutError:
                pass
            for future in [f for f in remaining if f.done()]:
                remaining.discard(future)
                if future.status == "error":
                    failed += _store_task_error(future, futures[future], folder)
                else:
                    failed += sum(row["status"] != "ok" for row in future.result())
            if progress is not None:
                done, running = _counts(client, futures, folder, cases)
                progress(done, failed, running, len(cases), result.dashboard)
    except BaseException:
        client.cancel(list(futures))
        raise


def _store_task_error(future: Any, group: list[Case], folder: Path) -> int:
    """A task that failed as a whole (not one of its cases): each case gets the error."""
    from .store import store

    exc = future.exception()
    count = 0
    for case in group:
        if not case_file(folder, case.hash).exists():
            store(folder, case.hash, {"case": case.index, "values": case.values,
                                      "status": f"task failed: {type(exc).__name__}: {exc}",
                                      "hash": case.hash, "model": case.model[:12]})
            count += 1
    return count


def _counts(client: Any, futures: dict[Any, list[Case]], folder: Path,
            cases: list[Case]) -> tuple[int, int]:
    """(done, running) cases: stored or refused; in a task processing on a worker."""
    done = sum(c.scenario is None or case_file(folder, c.hash).exists() for c in cases)
    try:
        processing = {key for keys in client.processing().values() for key in keys}
    except Exception:  # noqa: BLE001  (progress only)
        processing = set()
    running = sum(len(group) for future, group in futures.items() if future.key in processing)
    return done, min(running, len(cases) - done)
