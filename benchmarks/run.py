"""Development runner of the cost study.

    python benchmarks/run.py              # full study, writes benchmarks/results.md and .csv
    python benchmarks/run.py --quick      # smoke run, writes benchmarks/out/quick/results.md
    python benchmarks/run.py --sizes 8,16,32 --no-regimes
    python benchmarks/run.py --render-only   # rewrite the reports from the last bench.json

Runs :func:`splinedeform.bench.main` (BLAS threads not pinned: the library as it ships; its own files go to
``benchmarks/out/…``), then ``benchmarks/bench_evaluate.py``'s ``run(quick)`` when that file
exists, prints each line's fastest method and the goals, and writes the results with a note
on the machine.
"""

from __future__ import annotations

import argparse
import datetime
import importlib.util
import json
import sys
from pathlib import Path
from typing import Any

from splinedeform import bench
from splinedeform.bench.tables import readme_tables, verdict
from splinedeform.export import write_text

HERE = Path(__file__).resolve().parent
NOTE = ("Timings were taken on a shared 2-core machine while other work (test suites) ran "
        "on it, so they are indicative: repeated runs vary by tens of percent; ratios "
        "measured in one run are more stable than absolute times.")


def parse(argv: list[str] | None) -> argparse.Namespace:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    p.add_argument("--quick", action="store_true", help="smoke run (tiny nets)")
    p.add_argument("--sizes", help="comma-separated cells per direction, e.g. 8,16,32,64,128")
    p.add_argument("--budget", type=float, help="seconds per numerical run before stopping it")
    p.add_argument("--frames", type=int, help="number of frames")
    p.add_argument("--goals", action="store_true",
                   help="also the goals of the analytic path at scale (separate processes)")
    p.add_argument("--no-regimes", action="store_true",
                   help="only regime a (cost against net size), not b–e")
    p.add_argument("--methods", help="comma-separated numerical methods (default: the study's)")
    p.add_argument("--families", help="comma-separated problem families (clamped, region)")
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


def verdict_lines(rows: list[bench.Row]) -> list[str]:
    """``regime line cells: fastest method, how the analytic path fares`` per line."""
    lines: dict[tuple, list[bench.Row]] = {}
    for r in rows:
        lines.setdefault(r.line, []).append(r)
    out = []
    for (regime, case, family, cells), line in lines.items():
        name, fares = verdict(line)
        label = f"{regime} {family if regime == 'size' else case}"
        out.append(f"{label:42s} {cells:3d}²: fastest {name}; analytic path {fares}")
    return out


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
        result = bench.main(sizes=sizes, quick=args.quick, outdir=out, budget=args.budget,
                            frames=args.frames, goals=args.goals,
                            regimes_too=False if args.no_regimes else None,
                            methods=split(args.methods), families=split(args.families))
    evaluate, evaluated = evaluate_section(args.quick)
    print("\nfastest method of each line:")
    for line in verdict_lines(result["rows"]):
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
    command = " ".join(sys.argv[1:]) if argv is None else " ".join(argv)
    text = (f"# Benchmark results\n\n{args.note}\n\nRun {stamp} with "
            f"`python benchmarks/run.py{' ' + command if command else ''}`"
            f"; plots in `{out.relative_to(HERE.parent)}`.\n\n{body}{evaluate}")
    write_text(target / "results.md", text)
    write_text(target / "results.csv", bench.csv_text(result["rows"]))
    readme = write_text(out / "readme_tables.md", readme_tables(result["rows"], result["goals"]))
    print(f"written: {target / 'results.md'}, {target / 'results.csv'}, {readme}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
