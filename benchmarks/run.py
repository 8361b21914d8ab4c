"""Development runner of the cost study.

    python benchmarks/run.py              # full study, writes benchmarks/results.md and .csv
    python benchmarks/run.py --quick      # smoke run, writes benchmarks/out/quick/results.md
    python benchmarks/run.py --sizes 4,8,16,32 --budget 120
    python benchmarks/run.py --render-only   # rewrite the reports from the last bench.json

Runs :func:`splinedeform.bench.main` (its own files go to ``benchmarks/out/…``), then
``benchmarks/bench_evaluate.py``'s ``run(quick)`` when that file exists, prints the ratios
numerical / analytic, and writes the results with a note on the machine.
"""

from __future__ import annotations

import argparse
import datetime
import importlib.util
import json
import math
import sys
from pathlib import Path
from typing import Any

from splinedeform import bench, bench_goals
from splinedeform.export import write_text

HERE = Path(__file__).resolve().parent
NOTE = ("Timings were taken on a shared 2-core machine while other work (test suites) ran "
        "on it, so they are indicative: repeated runs vary by tens of percent; ratios "
        "measured in one run are more stable than absolute times.")


def parse(argv: list[str] | None) -> argparse.Namespace:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    p.add_argument("--quick", action="store_true", help="smoke run (tiny nets)")
    p.add_argument("--sizes", help="comma-separated cells per direction, e.g. 4,8,16,32,64")
    p.add_argument("--budget", type=float, help="seconds per numerical run before stopping it")
    p.add_argument("--frames", type=int, help="number of frames")
    p.add_argument("--no-goals", action="store_true", help="skip the goals at scale")
    p.add_argument("--methods", help="comma-separated numerical methods (default: the study's)")
    p.add_argument("--families", help="comma-separated problem families (clamped, region)")
    p.add_argument("--regimes", action="store_true",
                   help="also the regimes of splinedeform.bench_goals (horizon, load cases, "
                        "one state) and the goals of issue 10")
    p.add_argument("--note", default=NOTE, help="sentence on the machine for the results file")
    p.add_argument("--render-only", action="store_true",
                   help="rewrite the reports from the last run's bench.json, measuring nothing "
                        "(the evaluation benchmark still runs)")
    return p.parse_args(argv)


def evaluate_section(quick: bool) -> tuple[str, Any]:
    """Markdown of ``benchmarks/bench_evaluate.py``'s ``run(quick)``, when present."""
    path = HERE / "bench_evaluate.py"
    if not path.is_file():
        return "", None
    spec = importlib.util.spec_from_file_location("bench_evaluate", path)
    module = importlib.util.module_from_spec(spec)
    assert spec.loader is not None
    spec.loader.exec_module(module)
    result = module.run(quick)
    return "\n## Evaluation benchmark (`benchmarks/bench_evaluate.py`)\n\n" + as_markdown(result) + "\n", result


def as_markdown(result: Any) -> str:
    """A string as is; a list of dicts as a table; a dict as key/value lines."""
    if isinstance(result, str):
        return result
    if isinstance(result, dict):
        if "markdown" in result and isinstance(result["markdown"], str):
            return result["markdown"]
        return "\n".join(f"- {k}: {v}" for k, v in result.items())
    if isinstance(result, (list, tuple)) and result and all(isinstance(r, dict) for r in result):
        keys = list(dict.fromkeys(k for r in result for k in r))
        lines = ["| " + " | ".join(keys) + " |", "|---" * len(keys) + "|"]
        lines += ["| " + " | ".join(_text(r.get(k, "")) for k in keys) + " |" for r in result]
        return "\n".join(lines)
    return f"{result!r}"


def _text(value: Any) -> str:
    return f"{value:.4g}" if isinstance(value, float) else str(value)


def ratio_lines(rows: list[bench.Row]) -> list[str]:
    """``family cells: method ratio`` per size, numerical / analytic (≈ when extrapolated)."""
    lines = []
    for family in dict.fromkeys(r.family for r in rows):
        for cells in sorted({r.cells for r in rows if r.family == family}):
            here = [r for r in rows if r.family == family and r.cells == cells
                    and r.solver != "analytic"]
            parts = [f"{r.solver} {'≈' if r.status != 'ok' else ''}{r.ratio:.3g}×"
                     for r in here if math.isfinite(r.ratio)]
            lines.append(f"{family:8s} {cells:3d}×{cells:<3d}: " + ", ".join(parts))
    return lines


def plate_ratios(rows: list[bench.Row]) -> dict[int, tuple[float, float, str]]:
    """Per net size of the ``clamped`` family: (analytic s, fastest integrator s, its name);
    a run stopped at the budget counts with its extrapolated cost when that is the lowest."""
    plate: dict[int, tuple[float, float, str]] = {}
    for cells in sorted({r.cells for r in rows if r.family == "clamped"}):
        here = [r for r in rows if r.family == "clamped" and r.cells == cells]
        analytic = [r for r in here if r.solver == "analytic"]
        numerical = [r for r in here if r.solver != "analytic"]
        if not analytic:
            continue
        guess = bench.fastest_estimate(numerical)
        best = bench.fastest(numerical)
        if guess is not None:
            plate[cells] = (analytic[0].seconds, guess.estimate,
                            f"{guess.solver} (extrapolated from {guess.progress:.0%} of t_end)")
        elif best is not None:
            plate[cells] = (analytic[0].seconds, best.seconds, best.solver)
    return plate


def main(argv: list[str] | None = None) -> int:
    args = parse(argv)
    sizes = [int(s) for s in args.sizes.split(",")] if args.sizes else None
    out = HERE / "out" / ("quick" if args.quick else "full")
    if args.render_only:
        files = bench.render(out)
        record = json.loads((out / "bench.json").read_text(encoding="utf-8"))
        result = {"rows": [bench.Row(**r) for r in record["rows"]],
                  "goals": [bench.Goal(**g) for g in record["goals"]], "files": files}
    else:
        split = lambda text: None if text is None else [x.strip() for x in text.split(",")]  # noqa: E731
        with bench_goals.blas_threads(1) as threads:
            print(threads, flush=True)
            result = bench.main(sizes=sizes, quick=args.quick, outdir=out, budget=args.budget,
                                frames=args.frames, goals=False if args.no_goals else None,
                                methods=split(args.methods), families=split(args.families))
    regimes = ""
    saved = out / "regimes.json"
    record = None
    if args.regimes and not args.render_only:
        record = bench_goals.goals(say=lambda s: print(s, flush=True), quick=args.quick)
        saved.write_text(json.dumps(record, indent=1, default=str), encoding="utf-8")
    elif args.render_only and saved.is_file():
        record = json.loads(saved.read_text(encoding="utf-8"))
    if record is not None:
        regimes = ("\n## Regimes and goals (`splinedeform.bench_goals`)\n\n"
                   + bench_goals.markdown(record, plate_ratios(result["rows"])))
    evaluate, evaluated = evaluate_section(args.quick)
    print("\nratios numerical / analytic (time to the same frames at the same accuracy):")
    for line in ratio_lines(result["rows"]):
        print("  " + line)
    for row in evaluated if isinstance(evaluated, list) else []:
        if isinstance(row, dict) and "ratio" in row:
            print(f"  evaluation: {row.get('name', '?')}: ratio {_text(row['ratio'])}")
    for goal in result["goals"]:
        met = "—" if goal.met is None else ("met" if goal.met else "NOT met")
        print(f"  goal [{met}] {goal.name}: {goal.measured}")
    target = out if args.quick else HERE
    study_md = result["files"]["markdown"].read_text(encoding="utf-8")
    body = study_md.replace("\n## ", "\n### ").replace("# Cost study", "## Cost study", 1)
    stamp = datetime.datetime.now().strftime("%Y-%m-%d %H:%M")
    text = (f"# Benchmark results\n\n{args.note}\n\nRun {stamp} with "
            f"`python benchmarks/run.py{' ' + ' '.join(sys.argv[1:]) if argv is None and sys.argv[1:] else ''}`"
            f"; plots in `{out.relative_to(HERE.parent)}`.\n\n{body}{regimes}{evaluate}")
    write_text(target / "results.md", text)
    write_text(target / "results.csv", bench.csv_text(result["rows"]))
    print(f"written: {target / 'results.md'}, {target / 'results.csv'}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
