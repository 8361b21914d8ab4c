"""One task of a sweep: the cases of one model, solved on a worker, each result stored.

The model (surface, material, boundary) is built once; every case of the group is then a
load (and solve) case on that same :class:`~splinedeform.Model` object, which keeps its
modal basis and factorisations between solves. A case that fails gets its error in its
row and the group goes on; a case already stored in the output folder (by an earlier run,
or by this task before its worker was lost and the task rescheduled) is read back, not
computed again.
"""

from __future__ import annotations

import os
import time
from pathlib import Path
from typing import Any

from ..budget import check as check_budget
from ..errors import InputError
from ..pipeline import _prepare_outdir, _solve, _Stages, write_outputs
from ..scenario import Built, build_load
from ..scenario.build import _located, check_parameters
from .cases import Case
from .geometries import model_of
from .measure import figures
from .modal_cases import ModalReadout, prepare
from .store import CASES, store, stored

#: load cases read out together, their rows stored when the chunk completes
CHUNK_CASES = 50


def solve_group(cases: list[Case], folder: str, case_outputs: bool = False
                ) -> list[dict[str, Any]]:
    """Solve the cases of one model (equal ``Case.model``); store and return their rows.

    The load cases that :mod:`.modal_cases` can read out from modal coordinates are solved
    together, a chunk of them at a time, each chunk's rows stored as it completes; the
    others one by one through the pipeline. A batched row's ``wall_s`` is its share of the
    seconds its chunk took (the first chunk's share includes the model's build).
    """
    rows: dict[str, dict[str, Any]] = {}
    todo: list[Case] = []
    for case in cases:
        row = stored(folder, case.hash)
        if row is not None:
            rows[case.hash] = row
        elif all(case.hash != other.hash for other in todo):
            todo.append(case)
    start = time.perf_counter()
    shared, model_error = _build(todo[0]) if todo else (None, None)
    if model_error is not None:
        for case in todo:
            rows[case.hash] = _store(folder, case, {"status": model_error}, start)
            start = time.perf_counter()
    elif shared is not None:
        prepared = [(case, prepare(case.scenario, shared, case_outputs)) for case in todo]
        batch = [(case, p) for case, p in prepared if p is not None]
        if batch:
            readout = ModalReadout(shared)
            for i in range(0, len(batch), CHUNK_CASES):
                chunk = batch[i:i + CHUNK_CASES]
                found = readout.figures([p for _, p in chunk])
                share = (time.perf_counter() - start) / len(chunk)
                for (case, _), figures_of in zip(chunk, found):
                    if figures_of is None:      # not finite: the pipeline says why
                        figures_of = _solve_case(case, shared, folder, case_outputs)
                    rows[case.hash] = _store(folder, case, {"status": "ok", **figures_of},
                                             time.perf_counter() - share)
                start = time.perf_counter()
        for case, p in prepared:
            if p is None:
                figures_or_error = _solve_case(case, shared, folder, case_outputs)
                rows[case.hash] = _store(folder, case, figures_or_error, start)
                start = time.perf_counter()
    return [rows[case.hash] for case in cases]


def solve_groups(groups: list[list[Case]], folder: str, case_outputs: bool = False
                 ) -> list[dict[str, Any]]:
    """:func:`solve_group` for each of several groups (one task for models of few cases)."""
    return [row for group in groups for row in solve_group(group, folder, case_outputs)]


def _build(case: Case) -> tuple[Built | None, str | None]:
    """The model of a group, or the message of the error that stopped its build."""
    try:
        return model_of(case), None
    except InputError as exc:
        return None, str(exc)
    except Exception as exc:  # noqa: BLE001  (the row says it; the sweep goes on)
        return None, f"internal error: {type(exc).__name__}: {exc}"


def _store(folder: str, case: Case, figures_or_error: dict[str, Any], start: float
           ) -> dict[str, Any]:
    """The case's row (its figures or error, the seconds since ``start``), stored."""
    row = {"case": case.index, "values": case.values, **figures_or_error,
           "hash": case.hash, "model": case.model[:12],
           "wall_s": time.perf_counter() - start, "worker": _worker()}
    store(folder, case.hash, row)
    return row


def _solve_case(case: Case, shared: Built, folder: str, case_outputs: bool) -> dict[str, Any]:
    scenario = case.scenario
    assert scenario is not None
    try:
        check_parameters(scenario, shared.surface)
        with _located(scenario, "load"):
            load = build_load(scenario)
        built = Built(surface=shared.surface, model=shared.model, load=load, fixed=shared.fixed)
        check_budget(scenario, built.model, None)
        stages = _Stages(None)
        result = _solve(scenario, built, stages)
        if case_outputs and scenario.output.formats:
            outdir = _prepare_outdir(scenario, Path(folder) / CASES / case.hash)
            write_outputs(result, outdir, stages)
        return {"status": "ok", **figures(result)}
    except InputError as exc:
        return {"status": str(exc)}
    except Exception as exc:  # noqa: BLE001  (the row says it; the sweep goes on)
        return {"status": f"internal error: {type(exc).__name__}: {exc}"}


def _worker() -> str:
    """The Dask worker's address, or this process (outside a worker)."""
    try:
        from distributed import get_worker

        return str(get_worker().address)
    except (ImportError, ValueError):
        return f"pid {os.getpid()}"
