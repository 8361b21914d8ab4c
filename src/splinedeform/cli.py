"""The ``splinedeform`` command: run, demo, validate, info (and bench when available).

A thin layer over :mod:`splinedeform.scenario`: it reads the scenario, forwards the
command-line overrides, draws progress bars (stderr) and prints a closing summary
(stdout). Bad input (:class:`~splinedeform.errors.InputError`, which includes
:class:`~splinedeform.errors.ScenarioError`) prints its message on stderr and exits with
code 2, without a traceback unless ``--debug``; any other failure exits with code 1.
Ctrl-C during a run prints one line (where it stopped, what it left incomplete) and exits
with code 130.
"""

from __future__ import annotations

import importlib.util
import platform
import sys
import warnings
from contextlib import contextmanager
from importlib import metadata, resources
from pathlib import Path
from typing import Any, Iterator, Optional

import typer
from typer.core import TyperCommand, TyperGroup

from . import __version__
from .errors import InputError

EXIT_INPUT_ERROR = 2
EXIT_INTERNAL_ERROR = 1
#: exit status after Ctrl-C (128 + SIGINT), as shells report it
EXIT_INTERRUPTED = 130

#: optional modules reported by ``splinedeform info``: import name -> (distribution, use)
OPTIONAL = {
    "typer": ("typer", "command line"),
    "rich": ("rich", "progress bars and tables"),
    "meshio": ("meshio", "OBJ / STL / PLY / VTU meshes"),
    "matplotlib": ("matplotlib", "pictures and GIF animation frames"),
    "imageio": ("imageio", "GIF animation"),
    "PIL": ("pillow", "GIF encoding"),
    "imageio_ffmpeg": ("imageio-ffmpeg", "MP4 animation (extra: video)"),
    "pyvista": ("pyvista", "offscreen 3-D rendering (extra: render3d)"),
    "playwright": ("playwright", "viewer test in a headless browser"),
    "starlette": ("starlette", "sculpt server (extra: sculpt)"),
    "uvicorn": ("uvicorn", "sculpt server (extra: sculpt)"),
    "rhino3dm": ("rhino3dm", "openNURBS .3dm files (extra: cad)"),
    "OCP": ("cadquery-ocp-novtk", "STEP and IGES files, OpenCASCADE (extra: cad-step)"),
}



class _BareFlags:
    """Help lists on/off flags bare (``--quiet``), without a value type (``<bool>``)."""

    def get_params(self, ctx: Any) -> list[Any]:
        params: list[Any] = super().get_params(ctx)  # type: ignore[misc]
        for param in params:
            if getattr(param, "is_flag", False) and getattr(param, "metavar", None) is None:
                param.metavar = ""
        return params


class _Command(_BareFlags, TyperCommand):
    """A command whose help shows flags bare."""


class _Group(_BareFlags, TyperGroup):
    """The command group, its help showing flags bare."""


class _App(typer.Typer):
    """The command line; every command's help shows flags bare."""

    def command(self, *args: Any, cls: Any = None, **kwargs: Any) -> Any:
        return super().command(*args, cls=cls or _Command, **kwargs)


app = _App(name="splinedeform", cls=_Group, no_args_is_help=True, add_completion=False,
                  pretty_exceptions_enable=False,
                  help="Physical deformation of B-spline surfaces, solved analytically.")


def _print_version(value: bool) -> None:
    if value:
        typer.echo(f"splinedeform {__version__}")
        raise typer.Exit()


@app.callback()
def _options(version: bool = typer.Option(False, "--version", is_eager=True,
                                          callback=_print_version,
                                          help="Print the version and exit.")) -> None:
    """Physical deformation of B-spline surfaces, solved analytically."""

SCENARIO_ARG = typer.Argument(..., metavar="SCENARIO.toml", show_default=False,
                              help="Scenario file (TOML), see docs/scenario.md.")
OUTDIR_OPT = typer.Option(None, "-o", "--outdir", help="Output folder (created if missing). "
                                                       "[default: <scenario name>-output]")
QUIET_OPT = typer.Option(False, "--quiet", "-q", help="Print nothing but errors.")
DEBUG_OPT = typer.Option(False, "--debug", help="Show the full traceback of an error.")
OUTSIDE_OPT = typer.Option(False, "--allow-outside-paths",
                           help="Let the scenario read files outside its own folder "
                                "(surface.path); refused by default.")
BUDGET_OPT = typer.Option(None, "--budget", help="Raise the limits a run is estimated against "
                                                 "before it starts, e.g. memory=16GiB,disk=50GiB,"
                                                 "files=1e5,work=1e13 (inf lifts one). "
                                                 "[default: memory=4GiB,disk=4GiB,files=5000,"
                                                 "work=1e12]")


def _consoles() -> tuple[Any, Any]:
    """(stdout, stderr) rich consoles; wide when not a terminal, so paths are never cut."""
    from rich.console import Console

    out_width = None if sys.stdout.isatty() else 250
    err_width = None if sys.stderr.isatty() else 120
    return Console(width=out_width), Console(stderr=True, width=err_width)


#: widest line of ``splinedeform info`` (long values wrap inside their cell)
INFO_WIDTH = 100


@contextmanager
def _reported_errors(debug: bool) -> Iterator[None]:
    """Turn errors into a message on stderr and an exit code (a traceback only with --debug);
    warnings are one line each on stderr, ``warning: <message>`` (with their source line
    only with --debug)."""
    with warnings.catch_warnings():
        if not debug:
            warnings.showwarning = _print_warning
        with _errors_reported(debug):
            yield


@contextmanager
def _errors_reported(debug: bool) -> Iterator[None]:
    try:
        yield
    except (typer.Exit, typer.Abort, KeyboardInterrupt):
        raise
    except InputError as exc:
        if debug:
            raise
        _print_error(str(exc))
        raise typer.Exit(EXIT_INPUT_ERROR) from None
    except Exception as exc:  # noqa: BLE001  (any other failure: short message, exit 1)
        if debug:
            raise
        _print_error(f"internal error: {type(exc).__name__}: {exc}\n"
                     "(run again with --debug for the traceback)")
        raise typer.Exit(EXIT_INTERNAL_ERROR) from None


def _print_warning(message: Warning | str, category: type[Warning], filename: str,
                   lineno: int, file: Any = None, line: str | None = None) -> None:
    _, err = _consoles()
    err.print(f"[bold yellow]warning:[/] {_escape(str(message))}", highlight=False,
              soft_wrap=True)


def _print_error(message: str) -> None:
    _, err = _consoles()
    err.print(f"[bold red]error:[/] {_escape(message)}", highlight=False, soft_wrap=True)


def _escape(text: str) -> str:
    """``text`` shown literally: rich markup escaped, terminal control characters visible."""
    from rich.markup import escape

    from .terminal import printable

    return escape(printable(text))


def _table(title: str, rows: list[tuple[str, str]]) -> Any:
    from rich.table import Table

    table = Table(title=_escape(title), show_header=False, title_justify="left")
    table.add_column("what", style="bold")
    table.add_column("value", overflow="fold")
    for label, value in rows:
        table.add_row(_escape(label), _escape(value))
    return table


def _run(scenario: Any, outdir: Path, quiet: bool, budget: str | None = None) -> None:
    """Run a validated scenario with progress bars and print the summary table."""
    from ._progress import StageProgress
    from .budget import Budget
    from .pipeline import RunInterrupted, run, summary_rows

    limits = Budget.parse(budget) if budget is not None else None
    out, err = _consoles()
    try:
        with StageProgress(err, enabled=not quiet) as progress:
            result = run(scenario, outdir, progress=progress, budget=limits)
    except RunInterrupted as exc:          # Ctrl-C: one line, not a traceback
        err.print(_escape(str(exc)), style="bold yellow", highlight=False, soft_wrap=True)
        raise typer.Exit(EXIT_INTERRUPTED) from None
    if not quiet:
        out.print(_table(f"splinedeform: {scenario.title or scenario.name}",
                         summary_rows(result)))


@app.command("run")
def run_command(scenario: Path = SCENARIO_ARG, outdir: Optional[Path] = OUTDIR_OPT,
                method: Optional[str] = typer.Option(
                    None, "--method", help="Override solve.method: analytic, newmark, radau3, "
                                           "radau5, radau7, genalpha, rk45, "
                                           "dop853, radau, bdf."),
                frames: Optional[int] = typer.Option(
                    None, "--frames", help="Override solve.frames (replaces solve.times)."),
                physics: Optional[str] = typer.Option(
                    None, "--physics", help="Override material.physics: parametric (the "
                                            "paper's energy), intrinsic (on the surface) or "
                                            "shell (Kirchhoff–Love; needs E, nu, thickness)."),
                allow_outside_paths: bool = OUTSIDE_OPT, budget: Optional[str] = BUDGET_OPT,
                quiet: bool = QUIET_OPT, debug: bool = DEBUG_OPT) -> None:
    """Run a scenario file: build, solve, sample frames and write its outputs."""
    from .scenario import load_scenario, with_method, with_overrides

    with _reported_errors(debug):
        loaded = load_scenario(scenario, allow_outside_paths=allow_outside_paths)
        if method is not None:
            old = loaded.solve.method
            loaded, dropped = with_method(loaded, method, origin="--method")
            if dropped and not quiet:
                _, err = _consoles()
                err.print(f"--method {_escape(method)}: dropped {', '.join(dropped)} of "
                          f"{_escape(str(scenario))} (settings of method {old!r}, not used by "
                          f"{_escape(method)})", highlight=False, soft_wrap=True)
        if frames is not None:
            loaded = with_overrides(loaded, {"solve.frames": frames, "solve.times": None},
                                    origin="--frames")
        if physics is not None:
            loaded = with_overrides(loaded, {"material.physics": physics}, origin="--physics")
        _run(loaded, outdir or Path(f"{loaded.name}-output"), quiet, budget)


def demo_scenario() -> Any:
    """The built-in demo (package data ``splinedeform/data/demo.toml``) as a Scenario."""
    from .scenario import parse_scenario

    text = resources.files("splinedeform").joinpath("data/demo.toml").read_text("utf-8")
    return parse_scenario(text, source="demo.toml")


@app.command("demo")
def demo_command(outdir: Path = typer.Option(Path("demo-output"), "-o", "--outdir",
                                             help="Output folder (created if missing)."),
                 quiet: bool = QUIET_OPT, debug: bool = DEBUG_OPT) -> None:
    """Run the built-in demo: a clamped half sphere pushed in near the pole, every output."""
    with _reported_errors(debug):
        _run(demo_scenario(), outdir, quiet)


@app.command("validate")
def validate_command(scenario: Path = SCENARIO_ARG, allow_outside_paths: bool = OUTSIDE_OPT,
                     budget: Optional[str] = BUDGET_OPT, debug: bool = DEBUG_OPT) -> None:
    """Check a scenario file and print what it would run (with every default filled in);
    a run over its budget is refused here as by ``run``."""
    from .budget import Budget, check
    from .scenario import build, describe, load_scenario, scenario_to_toml
    from .terminal import printable

    with _reported_errors(debug):
        loaded = load_scenario(scenario, allow_outside_paths=allow_outside_paths)
        built = build(loaded)
        found = check(loaded, built.model, Budget.parse(budget) if budget is not None else None)
        out, _ = _consoles()
        rows = describe(loaded, built) + found.rows()
        out.print(_table(f"{scenario}: valid", rows))
        out.print(printable(scenario_to_toml(loaded)), markup=False, highlight=False)


@app.command("schema")
def schema_command() -> None:
    """Print the JSON Schema of scenario files (for editors: see docs/scenario.md)."""
    import json

    from .scenario.schema import json_schema

    sys.stdout.write(json.dumps(json_schema(), indent=2, ensure_ascii=False) + "\n")


def examples_directory() -> Path | None:
    """The ``examples/`` folder of a source checkout, if there is one."""
    candidate = Path(__file__).resolve().parents[2] / "examples"
    return candidate if candidate.is_dir() else None


def _optional_rows() -> list[tuple[str, str]]:
    """One row per optional package: its version if it imports, else why not."""
    rows = []
    for module, (dist, use) in OPTIONAL.items():
        try:
            importlib.import_module(module)
        except ImportError:
            rows.append((dist, f"not installed  ({use})"))
            continue
        except Exception as exc:  # noqa: BLE001  (installed but broken, e.g. a missing library)
            rows.append((dist, f"installed but fails to import: {type(exc).__name__}: {exc}  "
                               f"({use})"))
            continue
        try:
            version = metadata.version(dist)
        except metadata.PackageNotFoundError:
            version = "?"
        rows.append((dist, f"{version}  ({use})"))
    return rows


@app.command("info")
def info_command() -> None:
    """Version, optional extras that import, and where the examples live."""
    from rich.console import Console

    terminal = Console().width if sys.stdout.isatty() else INFO_WIDTH
    out = Console(width=min(terminal, INFO_WIDTH))
    examples = examples_directory()
    rows = [("splinedeform", __version__),
            ("python", f"{platform.python_version()} ({sys.executable})"),
            ("package", str(Path(__file__).resolve().parent)),
            ("examples", str(examples) if examples is not None
             else "not installed (see examples/ in the source repository)"),
            ("demo scenario", str(resources.files("splinedeform").joinpath("data/demo.toml")))]
    if examples is not None:
        rows.append(("example files", ", ".join(sorted(p.name for p in examples.glob("*.toml")))))
    out.print(_table("splinedeform info", rows))
    out.print(_table("optional packages", _optional_rows()))


#: default folder of ``splinedeform bench`` (``out/`` is git-ignored in a source checkout)
BENCH_OUTDIR = Path("out") / "bench"


def _register_bench() -> None:
    """Add ``splinedeform bench`` when the cost study module is installed."""
    try:
        available = importlib.util.find_spec("splinedeform.bench") is not None
    except (ImportError, ValueError):
        available = False
    if not available:
        return

    @app.command("bench")
    def bench_command(sizes: Optional[str] = typer.Option(
                          None, "--sizes", help="Comma-separated net sizes, e.g. 8,16,32."),
                      quick: bool = typer.Option(
                          False, "--quick", help="A smoke run of a few seconds: nets of 3×3 "
                                                 "and 4×4 cells, target 1e-3, regime a only."),
                      outdir: Path = typer.Option(BENCH_OUTDIR, "-o", "--outdir",
                                                  help="Output folder (created if missing)."),
                      quiet: bool = QUIET_OPT, debug: bool = DEBUG_OPT) -> None:
        """Cost study: analytic against numerical solvers, cost against net size."""
        from . import bench

        with _reported_errors(debug):              # bench.main limits the BLAS threads
            parsed = None
            if sizes is not None:
                try:
                    parsed = [int(s) for s in sizes.split(",") if s.strip()]
                except ValueError:
                    raise InputError(f"--sizes must be comma-separated integers, got "
                                     f"{sizes!r}") from None
            bench.main(parsed, quick, outdir, quiet)


_register_bench()


def _register_sculpt() -> None:
    """Add ``splinedeform sculpt`` (its server needs the extra 'sculpt')."""
    from .sculpt.command import register

    register(app)


_register_sculpt()


def main() -> None:
    """Entry point of the ``splinedeform`` script."""
    app()


if __name__ == "__main__":
    main()
