"""``report.md`` of a sweep: what was run, how many models for how many cases, the plots.

One PNG per axis (``plot_<axis>.png``): each result (largest displacement, lowest
frequency, energy, first probe — those the cases have) against the axis' values; with two
axes, a pair plot (``pairs.png``): the cases in the plane of the two axes, coloured by the
largest displacement. Axis values that are not numbers (boundary presets) are placed at
equally spaced positions labelled with the values.
"""

from __future__ import annotations

import importlib
import math
import re
import threading
from pathlib import Path
from typing import Any

from ..export.atomic import write_text, write_with
from .store import columns, flat

#: the results plotted, those present in the rows
PLOTTED = ("max_displacement", "omega_1", "strain_energy", "strain_energy_max", "p1_max")


#: what writing the tables and the plots imports (the Agg canvas: savefig's first use)
WRITERS = ("pyarrow.parquet", "matplotlib.figure", "matplotlib.backends.backend_agg")


def import_writers_in_background() -> None:
    """Import :data:`WRITERS` in a thread, for a sweep whose cases leave a core idle: the
    tables and plots are then written without waiting for the imports."""
    def load() -> None:
        for name in WRITERS:
            try:
                importlib.import_module(name)
            except ImportError:            # the writer says so when it runs
                return

    threading.Thread(target=load, name="splinedeform-report-imports", daemon=True).start()


def write_report(result: Any) -> dict[str, Path]:
    """Write ``report.md`` (and its plots when the sweep asks) to ``result.folder``."""
    sweep, folder = result.sweep, Path(result.folder)
    rows = [flat(row) for row in result.rows]
    ok = [row for row in rows if row["status"] == "ok"]
    axes = [name for name in columns(rows)      # the axis columns whose values vary
            if any(name == a.key or name.startswith(a.key + "[") for a in sweep.axes)
            and len({repr(row.get(name)) for row in rows}) > 1]
    plotted = [name for name in PLOTTED if any(_number(row.get(name)) for row in ok)]
    files: dict[str, Path] = {}
    if sweep.plots and ok and plotted:
        for axis in axes:
            files[f"plot {axis}"] = _plot_axis(folder, ok, axis, plotted)
        if len(axes) == 2:
            files["pairs"] = _pair_plot(folder, ok, axes, plotted[0])
    solved = sum(row.get("status") == "ok" or "wall_s" in row for row in rows)
    models = len({row["model"] for row in rows if "wall_s" in row})
    lines = [f"# {sweep.title or 'Sweep of ' + Path(sweep.base.source).name}", ""]
    if sweep.description:
        lines += [sweep.description, ""]
    lines += [f"- base scenario: `{sweep.base.source}`",
              f"- design: {sweep.design}" + (f", n = {sweep.n}, seed = {sweep.seed}"
                                             if sweep.design != "grid" else ""),
              f"- axes: {', '.join(f'`{a.key}`' for a in sweep.axes)}",
              f"- cases: {len(rows)}; ok {len(ok)}, failed {len(rows) - len(ok)}",
              f"- models: {models} solved for {solved} cases (cases differing only in their "
              "loads or solve share one model and its modal basis)",
              f"- this run: {result.computed} cases computed on {result.models} models, "
              f"{result.reused} read back from earlier runs; {result.workers} workers",
              "- results: `results.parquet`, `results.csv`", ""]
    failures = [row for row in rows if row["status"] != "ok"]
    if failures:
        lines += ["## Failed cases", "", "| case | error |", "|---|---|"]
        lines += [f"| {row['case']} | {_cell(str(row['status']))} |" for row in failures]
        lines.append("")
    plots = [(name, path) for name, path in files.items()]
    if plots:
        lines += ["## Plots", ""]
        lines += [f"![{name}]({path.name})" for name, path in plots]
        lines.append("")
    files["report"] = write_text(folder / "report.md", "\n".join(lines))
    return files


def _cell(text: str) -> str:
    return text.replace("|", "\\|").replace("\n", "<br>")


def _number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and \
        math.isfinite(value)


def _positions(rows: list[dict[str, Any]], axis: str) -> tuple[list[float], list[str] | None]:
    """x positions of the rows along an axis, and tick labels for non-numeric values."""
    values = [row.get(axis) for row in rows]
    if all(_number(v) for v in values):
        return [float(v) for v in values], None
    labels = sorted({str(v) for v in values})
    return [float(labels.index(str(v))) for v in values], labels


def _plot_axis(folder: Path, rows: list[dict[str, Any]], axis: str,
               results: list[str]) -> Path:
    from matplotlib.figure import Figure       # no pyplot: no global figures, no backend

    x, labels = _positions(rows, axis)
    fig = Figure(figsize=(3.6 * len(results), 3.2))
    panels = fig.subplots(1, len(results), squeeze=False)
    for panel, name in zip(panels[0], results):
        y = [row.get(name) if _number(row.get(name)) else math.nan for row in rows]
        panel.plot(x, y, "o", markersize=4)
        panel.set_xlabel(axis)
        panel.set_ylabel(name)
        if labels is not None:
            panel.set_xticks(range(len(labels)), labels, rotation=30)
        elif min(x) > 0 and max(x) / min(x) > 50:
            panel.set_xscale("log")
    # fixed margins (inches over the figure's width) rather than tight_layout, which draws
    # the figure twice more
    width = 3.6 * len(results)
    fig.subplots_adjust(left=0.8 / width, right=1.0 - 0.15 / width, top=0.95,
                        bottom=0.3 if labels is not None else 0.17, wspace=0.45)
    path = folder / f"plot_{_slug(axis)}.png"
    write_with(path, lambda tmp: fig.savefig(tmp, dpi=90, format="png"))
    return path


def _pair_plot(folder: Path, rows: list[dict[str, Any]], axes: list[str], result: str) -> Path:
    from matplotlib.figure import Figure

    (x, xl), (y, yl) = _positions(rows, axes[0]), _positions(rows, axes[1])
    c = [row.get(result) if _number(row.get(result)) else math.nan for row in rows]
    fig = Figure(figsize=(4.8, 4.0))
    panel = fig.subplots()
    dots = panel.scatter(x, y, c=c, s=30)
    fig.colorbar(dots, ax=panel, label=result)
    panel.set_xlabel(axes[0])
    panel.set_ylabel(axes[1])
    if xl is not None:
        panel.set_xticks(range(len(xl)), xl)
    if yl is not None:
        panel.set_yticks(range(len(yl)), yl)
    fig.tight_layout()
    path = folder / "pairs.png"
    write_with(path, lambda tmp: fig.savefig(tmp, dpi=90, format="png"))
    return path


def _slug(name: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", name).strip("_")
