"""Design studies: sweeps of a scenario's keys over a design space, solved on Dask.

A sweep file (``docs/sweep.md``) names a base scenario and its axes — any scenario key,
loads included — combined by a grid, a random (Monte Carlo) or a Latin-hypercube design.
:func:`sweep` runs every case on a Dask cluster (a local one of worker processes, or an
existing scheduler), cases of one model sharing its modal basis, each result stored as
it completes so that nothing is lost and an interrupted sweep resumes; it writes one row
per case to ``results.parquet`` / ``results.csv`` and a ``report.md`` with plots.

Modules, one idea each:

- :mod:`.schema` — the sweep file as pydantic models (``splinedeform schema --sweep``);
- :mod:`.read` — TOML text → validated :class:`Sweep`, problems located at their lines;
- :mod:`.keys` — axis keys: checked against the scenario's keys, and set in its tables;
- :mod:`.design` — the axes' values combined into design points;
- :mod:`.cases` — each point as a validated scenario, its content hash and its model;
- :mod:`.solve` — one task: the cases of one model, each result stored atomically;
- :mod:`.measure` — the figures of one solved case (one row);
- :mod:`.store` — per-case result files and the assembled tables;
- :mod:`.cluster` — the Dask client: a loopback ``LocalCluster`` or a scheduler;
- :mod:`.run` — the whole sweep: plan, skip stored cases, submit, wait, assemble;
- :mod:`.report` — ``report.md`` and its plots;
- :mod:`.command` — ``splinedeform sweep``.
"""

from __future__ import annotations

from .read import AxisSpec, Sweep, load_sweep, parse_sweep
from .run import SweepResult, sweep

__all__ = ["AxisSpec", "Sweep", "SweepResult", "load_sweep", "parse_sweep", "sweep"]
