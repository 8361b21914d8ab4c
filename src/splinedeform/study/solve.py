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
from ..scenario.build import _located, build_model, check_parameters
from .cases import Case
from .measure import figures
from .store import CASES, store, stored


def solve_group(cases: list[Case], folder: str, case_outputs: bool = False
                ) -> list[dict[str, Any]]:
    """Solve the cases of one model (equal ``Case.model``); store and return their rows."""
    rows: list[dict[str, Any]] = []
    shared: Built | None = None
    model_error: str | None = None
    for case in cases:
        row = stored(folder, case.hash)
        if row is not None:
            rows.append(row)
            continue
        start = time.perf_counter()
        if shared is None and model_error is None:
            try:
                shared = build_model(case.scenario)
            except InputError as exc:
                model_error = str(exc)
            except Exception as exc:  # noqa: BLE001  (the row says it; the sweep goes on)
                model_error = f"internal error: {type(exc).__name__}: {exc}"
        if model_error is not None:
            figures_or_error: dict[str, Any] = {"status": model_error}
        else:
            assert shared is not None
            figures_or_error = _solve_case(case, shared, folder, case_outputs)
        row = {"case": case.index, "values": case.values, **figures_or_error,
               "hash": case.hash, "model": case.model[:12],
               "wall_s": time.perf_counter() - start, "worker": _worker()}
        store(folder, case.hash, row)
        rows.append(row)
    return rows


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
