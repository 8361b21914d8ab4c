"""The study's report: markdown tables (regime a per family, regimes b–e, goals) and CSV.

A cell of a run reads ``time (×ratio to the fastest of its line; error reached)``; the last
two columns name the fastest method of the line and say how the analytic path fares
against it: ``wins, ×r ahead`` (the next fastest is ``r`` times slower) or ``we lose ×r``.
"""

from __future__ import annotations

import csv
import io
import math
from collections.abc import Sequence
from dataclasses import asdict

from .bookkeeping import Row, fastest, fastest_estimate, fitted_slope
from .cases import FORCE_AT, HEAVY, LIGHT, PLATE, REGION_RADIUS
from .config import Study
from .goals import Goal

NAMES = {"analytic": "analytic (automatic modes)", "analytic-all": "analytic (all modes)",
         "radau7": "Radau IIA-7", "radau3": "Radau IIA-3", "genalpha": "gen-α",
         "radau": "solve_ivp Radau", "bdf": "solve_ivp BDF", "rk45": "RK45",
         "dop853": "DOP853", "newmark": "Newmark"}


def fmt(value: float, unit: str = "", digits: int = 3) -> str:
    if not math.isfinite(value):
        return "—"
    return f"{value:.{digits}g}{unit}"


def cell(row: Row | None) -> str:
    """A run as a table cell (see the module docstring)."""
    if row is None:
        return "—"
    ratio = f"×{fmt(row.ratio)}"
    if row.status in ("ok", "exact"):
        error = f"; {row.error:.0e}" if math.isfinite(row.error) else ""
        if row.error == 0.0:                  # fell back to all modes: the reference itself
            error = "; = all modes"
        return f"{fmt(row.seconds, ' s')} ({ratio}{error})"
    if row.status == "over budget" and not math.isfinite(row.estimate):
        return f"> budget: {fmt(row.seconds, ' s')} for {row.progress:.0%} of t_end ({ratio} and more)"
    if row.status == "over budget":
        return f"> budget at {row.progress:.0%} of t_end, ≈{fmt(row.estimate, ' s')} (≈{ratio})"
    if row.status == "not run":
        return f"not run, ≈{fmt(row.estimate, ' s')} forecast (≈{ratio})"
    if row.status == "skipped" and not math.isfinite(row.estimate):
        return "skipped (over budget on a smaller net)"
    if row.status == "skipped":
        return f"skipped, ≈{fmt(row.estimate, ' s')} forecast (≈{ratio})"
    return f"not reached ({row.error:.0e})"


def verdict(line: Sequence[Row]) -> tuple[str, str]:
    """``(fastest method, how the analytic path fares)`` of a line."""
    best, guess = fastest(line), fastest_estimate(line)
    if guess is not None:
        best = guess
    if best is None:
        return "—", "—"
    name = NAMES.get(best.solver, best.solver) + (" (extrapolated)" if best is guess else "")
    analytic = fastest([r for r in line if r.analytic])
    if analytic is None:
        return name, "—"
    if best.analytic:
        others = [r.cost for r in line if not r.analytic and math.isfinite(r.cost)
                  and r.status in ("ok", "over budget")]
        if others:
            return name, f"wins, ×{fmt(min(others) / analytic.seconds)} ahead"
        forecast = [r.cost for r in line if not r.analytic and math.isfinite(r.cost)]
        if forecast:
            return name, f"wins, ≈×{fmt(min(forecast) / analytic.seconds)} ahead (forecast)"
        stopped = [r.seconds for r in line if r.status == "over budget"]
        if stopped:                                     # stopped too early to extrapolate
            return name, f"wins, ≥ ×{fmt(min(stopped) / analytic.seconds)} ahead"
        return name, "wins"
    return name, f"**we lose** ×{fmt(analytic.seconds / best.cost)}"


def _modes(row: Row | None) -> str:
    if row is None or row.status not in ("ok", "exact"):
        return "—"
    if row.modes >= row.n_free or not row.modes:
        return "all"
    if not math.isfinite(row.bound):                # made finer than the bound asked
        return f"{row.modes} (√2 steps past the bound's count)"
    return f"{row.modes} (bound {row.bound:.0e})"


def size_table(rows: Sequence[Row], study: Study, family: str) -> str:
    fam = [r for r in rows if r.regime == "size" and r.family == family]
    methods = list(study.methods)
    head = (["cells", "free", "analytic (automatic modes)", "modes (a-priori bound)",
             "analytic (all modes)"] + [NAMES[m] for m in methods]
            + ["fastest", "analytic path"])
    out = ["| " + " | ".join(head) + " |", "|---" * len(head) + "|"]
    for cells in sorted({r.cells for r in fam}):
        here = {r.solver: r for r in fam if r.cells == cells}
        any_row = next(iter(here.values()))
        name, fares = verdict(list(here.values()))
        out.append("| " + " | ".join(
            [f"{cells}×{cells}", str(any_row.n_free), cell(here.get("analytic")),
             _modes(here.get("analytic")), cell(here.get("analytic-all"))]
            + [cell(here.get(m)) for m in methods] + [name, fares]) + " |")
    notes = [f"- {r.cells}×{r.cells}: {r.note}" for r in fam
             if r.note and (r.solver == "analytic" or r.status == "not run")]
    checks = [f"- {r.cells}×{r.cells}: all modes {r.note}" for r in fam
              if r.solver == "analytic-all" and r.status == "exact" and r.note]
    text = "\n".join(out) + "\n"
    if notes or checks:
        text += "\nReferences and checks:\n\n" + "\n".join(checks + notes) + "\n"
    text += "\n" + _settings_table(fam, ["analytic", "analytic-all"] + methods)
    return text


def _settings_table(fam: list[Row], solvers: list[str]) -> str:
    sizes = sorted({r.cells for r in fam})
    out = ["Settings found (cheapest reaching the target) and cost slopes (time ∝ n_free^p, "
           "least squares over the three largest nets measured or extrapolated):", "",
           "| solver | " + " | ".join(f"{c}×{c}" for c in sizes) + " | slope p |",
           "|---" * (len(sizes) + 2) + "|"]
    for solver in solvers:
        by = {r.cells: r for r in fam if r.solver == solver}
        cells = [(by[c].setting if by[c].status in ("ok", "exact") else
                  f"> budget at {by[c].setting}" if by[c].status == "over budget" else
                  by[c].status) if c in by else "—" for c in sizes]
        out.append(f"| {NAMES.get(solver, solver)} | " + " | ".join(cells)
                   + f" | {fmt(fitted_slope(list(by.values())), digits=2)} |")
    return "\n".join(out) + "\n"


def regime_table(rows: Sequence[Row]) -> str:
    lines: dict[tuple, list[Row]] = {}
    for r in rows:
        if r.regime != "size":
            lines.setdefault(r.line, []).append(r)
    head = ["regime", "line", "cells", "analytic (automatic modes)", "modes (a-priori bound)",
            "analytic (all modes)", "Radau IIA-7", "its setting", "fastest", "analytic path"]
    out = ["| " + " | ".join(head) + " |", "|---" * len(head) + "|"]
    for (regime, case, _, cells), line in lines.items():
        here = {r.solver: r for r in line}
        radau = here.get("radau7")
        name, fares = verdict(line)
        out.append("| " + " | ".join(
            [regime, case, f"{cells}²", cell(here.get("analytic")), _modes(here.get("analytic")),
             cell(here.get("analytic-all")), cell(radau),
             radau.setting if radau is not None else "—", name, fares]) + " |")
    return "\n".join(out) + "\n"


def goals_table(goals: Sequence[Goal]) -> str:
    out = ["| goal | target | measured (integrator time / analytic time) | met |",
           "|---|---|---|---|"]
    for g in goals:
        met = "—" if g.met is None else ("yes" if g.met else "**no**")
        out.append(f"| {g.name} | {g.target} | {g.measured} | {met} |")
    text = "\n".join(out) + "\n"
    for g in goals:
        if g.limit:
            text += f"\n*{g.name}*: {g.limit}.\n"
    return text


def problem_text(study: Study) -> str:
    m = PLATE
    return (f"cubic open-knot plate on the unit square, μ = {m.mass:g}, w10 = w01 = {m.w10:g}, "
            f"w20 = w11 = w02 = {m.w20:g}, damping γ = {m.damping:g}, Rayleigh β = "
            f"{m.rayleigh:g} (light: γ = {LIGHT.damping:g}, β = {LIGHT.rayleigh:g}; heavy: "
            f"γ = {HEAVY.damping:g}); point force (0, 0, -1) at {FORCE_AT} on at t = 0, off at "
            f"t_end/2; t_end = 10 periods of the lowest mode; {study.frames} frames; accuracy "
            f"target {study.target:g} (max relative error of the control points at the "
            f"frames, against the reference); budget {study.budget:g} s per numerical run "
            f"({study.large_budget:g} s above 64×64). Family `clamped`: all edges clamped. "
            f"Family `region`: only the control points in the central disc of radius "
            f"{REGION_RADIUS} move (up to {study.region_max}×{study.region_max}). Times are "
            "from scratch and include the assembly (regime c: the model exists for both); "
            "analytic times are the median of three runs when one run takes < 3 s, numerical "
            "runs are timed once.")


LEGEND = ("Cells: total time (×ratio to the fastest run of the line; error reached). "
          "`> budget`: stopped at the budget, the full run extrapolated from the simulated time "
          "reached (below 5 % of t_end nothing is extrapolated and the ratio is a lower bound); "
          "`skipped`: forecast from the smaller nets; `not run`: forecast from the measured "
          "growth of the smaller nets, never measured. Analytic: the README's call as it "
          "ships, `Model.dynamic(load, t_end)` then `control_points(frames)`: modes chosen "
          "for the default 1e-8 (largest control-point coordinate error over the largest "
          "static displacement, at any time), library's own thread setting; its error is "
          "measured against the reference. `= all modes`: the default took all modes, the "
          "reference itself.")


def markdown(rows: list[Row], goals: list[Goal], study: Study, seconds: float,
             machine: str, threads: str, load: str) -> str:
    """The whole report."""
    out = ["# Cost study: analytic against numerical solution", "",
           f"Machine: {machine}. {threads}; load average {load}. Study time {seconds:.0f} s.",
           "", "Problem: " + problem_text(study), "", LEGEND, ""]
    for family in study.families:
        if any(r.family == family and r.regime == "size" for r in rows):
            out += [f"## a. Cost against net size, family `{family}`", "",
                    size_table(rows, study, family)]
    if any(r.regime != "size" for r in rows):
        out += ["## b–e. Horizon, load cases, one state, probes", "", regime_table(rows)]
    if goals:
        out += ["## Goals", "", goals_table(goals)]
    return "\n".join(out)


CSV_FIELDS = list(Row.__dataclass_fields__)


def csv_text(rows: list[Row]) -> str:
    buffer = io.StringIO()
    writer = csv.DictWriter(buffer, fieldnames=CSV_FIELDS, lineterminator="\n")
    writer.writeheader()
    for row in rows:
        writer.writerow({k: (f"{v:.6g}" if isinstance(v, float) else v)
                         for k, v in asdict(row).items()})
    return buffer.getvalue()


def readme_tables(rows: Sequence[Row], goals: Sequence[Goal]) -> str:
    """Compact tables for the README: regime a (family ``clamped``), regimes b–e, goals."""
    out = ["| cells | free | analytic, automatic modes | analytic, all modes | fastest "
           "integrator at the target | analytic path |", "|---:|---:|---|---|---|---|"]
    size = [r for r in rows if r.regime == "size" and r.family == "clamped"]
    for cells in sorted({r.cells for r in size}):
        here = [r for r in size if r.cells == cells]
        by = {r.solver: r for r in here}
        numerical = [r for r in here if not r.analytic]
        best = fastest_estimate(numerical) or fastest(numerical)
        out.append(f"| {cells}² | {here[0].n_free} | {_short(by.get('analytic'))} | "
                   f"{_short(by.get('analytic-all'))} | {_short(best, setting=True)} | "
                   f"{verdict(here)[1]} |")
    lines: dict[tuple, list[Row]] = {}
    for r in rows:
        if r.regime != "size":
            lines.setdefault(r.line, []).append(r)
    if lines:
        out += ["", "| regime | line | cells | analytic, automatic modes | analytic, all modes "
                "| Radau IIA-7 | analytic path |", "|---|---|---:|---|---|---|---|"]
    for (regime, case, _, cells), line in lines.items():
        by = {r.solver: r for r in line}
        out.append(f"| {regime} | {case} | {cells}² | {_short(by.get('analytic'))} | "
                   f"{_short(by.get('analytic-all'))} | {_short(by.get('radau7'), setting=True, name=False)}"
                   f" | {verdict(line)[1]} |")
    if goals:
        out += ["", "| goal | target | measured | met |", "|---|---|---|---|"]
        out += [f"| {g.name} | {g.target} | {g.measured.split(':')[0]} | "
                f"{'—' if g.met is None else ('yes' if g.met else '**no**')} |" for g in goals]
    return "\n".join(out) + "\n"


def _short(row: Row | None, setting: bool = False, name: bool = True) -> str:
    if row is None:
        return "—"
    label = f"{NAMES.get(row.solver, row.solver)} " if setting and name else ""
    if row.status in ("ok", "exact"):
        extra = row.setting if setting else (
            f"{row.modes} modes" if row.solver == "analytic" and 0 < row.modes < row.n_free
            else "")
        return f"{label}{fmt(row.seconds, ' s')}" + (f" ({extra})" if extra else "")
    if row.status == "over budget" and math.isfinite(row.estimate):
        return f"{label}≈{fmt(row.estimate, ' s')} (stopped at {row.progress:.0%}, extrapolated)"
    if row.status == "over budget":
        return f"{label}> {fmt(row.seconds, ' s')} (stopped at the budget)"
    if row.status in ("not run", "skipped"):
        return f"{label}not run, ≈{fmt(row.estimate, ' s')} forecast"
    return f"{label}not reached"
