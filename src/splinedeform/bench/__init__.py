"""The cost study: the analytic solution against numerical integrators, as a user needs it.

Every method runs at its cheapest setting reaching the target accuracy (the integrators'
settings a factor √2 apart, the analytic path's mode count chosen by an a-priori bound and
verified), and every line of the report gives each run's ratio to the *fastest* run of the
line and says where the analytic path loses. Regimes (issue 10):

a. cost against net size at a fixed horizon (:mod:`.sweep`);
b–e. cost against the horizon for light and heavy damping, each additional load case, one
   state at an arbitrary time, probes against whole nets (:mod:`.regimes`).

Modules: :mod:`.cases` (problems, error measure), :mod:`.search` (the setting search),
:mod:`.timing` (budget, BLAS threads, machine), :mod:`.bookkeeping` (rows, ratios,
forecasts), :mod:`.analytic` (automatic and all-modes rows, the reference), :mod:`.goals`,
:mod:`.tables` and :mod:`.plots` (the report), :mod:`.scale` (goals at scale).

Run it with ``splinedeform bench`` or :func:`main`.
"""

from __future__ import annotations

import json
import os
import time
from collections.abc import Callable, Sequence
from dataclasses import asdict
from pathlib import Path
from typing import Any

from ..errors import InputError
from ..export import write_text
from . import regimes, sweep
from .bookkeeping import Row, set_ratios
from .cases import FAMILIES, Case, build_model, make_case, reference_t_end, study_load
from .config import QUICK, Study, from_record, make_study
from .goals import Goal, issue_goals
from .plots import plot
from .search import DEFAULT_METHODS, NUMERICAL, substeps
from .tables import csv_text, markdown
from .timing import Attempt, attempt, blas_threads, load_average, machine

__all__ = ["main", "render", "Study", "QUICK", "Row", "Case", "Goal", "Attempt", "FAMILIES",
           "DEFAULT_METHODS", "NUMERICAL", "attempt", "substeps", "blas_threads",
           "build_model", "make_case", "reference_t_end", "study_load", "csv_text"]


def main(sizes: Sequence[int] | None = None, quick: bool = False,
         outdir: str | os.PathLike[str] = "out/bench", quiet: bool = False,
         frames: int | None = None, target: float | None = None, budget: float | None = None,
         methods: Sequence[str] | None = None, families: Sequence[str] | None = None,
         goals: bool | None = None, regimes_too: bool | None = None,
         threads: int | None = None) -> dict[str, Any]:
    """Run the cost study and write its results to ``outdir``; ``threads`` pins BLAS to that
    many threads for the whole study (default: not pinned, the library as it ships).

    Files: ``bench.json`` (every number, see :func:`render`), ``bench.md`` (the tables and
    goals), ``bench.csv`` (one row per run) and ``cost_<family>.png`` (log–log time against
    free control points with fitted slopes).

    Parameters
    ----------
    sizes : cells per direction (default 8, 16, 32, 64, 128; quick: 3, 4).
    quick : a short smoke run (:data:`QUICK`: 3×3 and 4×4 nets, 20 frames, target 1e-3,
        5 s budget, Radau IIA-7/-3 and generalised-α, no regimes b–e, no goals at scale).
    outdir : output folder (created).
    quiet : print nothing.
    frames, target, budget, methods, families, goals, regimes_too : override the
        :class:`Study` defaults (``goals``: the goals at scale; ``regimes_too``: b–e).

    Returns
    -------
    dict with ``rows`` (list of :class:`Row`), ``goals`` (list of :class:`Goal`),
    ``scale`` (raw goal measurements), ``files`` (paths written), ``study`` and ``seconds``.
    """
    study = make_study(sizes, quick, frames, target, budget, methods, families, goals,
                       regimes_too)
    out = Path(outdir)
    out.mkdir(parents=True, exist_ok=True)
    say: Callable[[str], None] = (lambda s: None) if quiet else (lambda s: print(s, flush=True))
    with blas_threads(threads) as setting:
        say(setting)
        load_before = load_average()
        start = time.perf_counter()
        rows: list[Row] = []
        for family in study.families:
            rows += sweep.study_family(family, study, say)
        if study.regimes:
            rows += regimes.run(study, say)
        set_ratios(rows)
        goal_list = issue_goals(rows, study.frames, study.target)
        raw: dict[str, dict] = {}
        if study.goals:
            from .scale import scale_goals

            more, raw = scale_goals(say)
            goal_list += more
        elapsed = time.perf_counter() - start
    record = {"study": asdict(study), "rows": [asdict(r) for r in rows],
              "goals": [asdict(g) for g in goal_list], "scale": raw, "seconds": elapsed,
              "machine": machine(), "threads": setting,
              "load": f"{load_before} at the start, {load_average()} at the end"}
    files = {"json": write_text(out / "bench.json", json.dumps(record, indent=1))}
    files.update(render(out))
    for g in goal_list:
        say(f"goal: {g.name}: {g.measured} "
            f"[{'—' if g.met is None else ('met' if g.met else 'NOT met')}]")
    say(f"written: {', '.join(str(p) for p in files.values())}")
    return {"rows": rows, "goals": goal_list, "scale": raw, "files": files, "study": study,
            "seconds": elapsed}


def render(outdir: str | os.PathLike[str]) -> dict[str, Path]:
    """Write ``bench.md``, ``bench.csv`` and the plots from the ``bench.json`` of a study run.

    Lets the report be regenerated without measuring again.
    """
    out = Path(outdir)
    try:
        record = json.loads((out / "bench.json").read_text(encoding="utf-8"))
        study = from_record(record["study"])
        rows = [Row(**r) for r in record["rows"]]
        goals = [Goal(**g) for g in record["goals"]]
    except (OSError, ValueError, KeyError, TypeError) as exc:
        raise InputError(f"cannot read the study results {out / 'bench.json'}: {exc}") from None
    text = markdown(rows, goals, study, record["seconds"], record.get("machine", "?"),
                    record.get("threads", "BLAS threads not recorded"),
                    record.get("load", "not recorded"))
    files = {"markdown": write_text(out / "bench.md", text),
             "csv": write_text(out / "bench.csv", csv_text(rows))}
    for family in study.families:
        if any(r.family == family and r.regime == "size" for r in rows):
            files[f"plot_{family}"] = plot(rows, family, out / f"cost_{family}.png",
                                           study.methods)
    return files
