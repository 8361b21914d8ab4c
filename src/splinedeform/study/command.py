"""``splinedeform sweep SWEEP.toml -o OUT``: run a design study on Dask, print its summary.

Progress (cases done, failed, running; the dashboard's address) goes to stderr, the
summary to stdout. Ctrl-C stops the sweep: the cases stored so far stay in ``OUT`` and the
same command run again computes only the others (exit code 130).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Optional

import typer

EXIT_INTERRUPTED = 130


class _SweepBar:
    """A rich bar of the cases done, with the failed and running counts (a no-op if quiet)."""

    def __init__(self, console: Any, enabled: bool) -> None:
        self.progress: Any = None
        self.task: Any = None
        self.shown_dashboard = False
        self.console = console
        if enabled:
            from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn

            self.progress = Progress(TextColumn("cases"), BarColumn(), MofNCompleteColumn(),
                                     TextColumn("{task.description}"), console=console,
                                     transient=False)

    def __enter__(self) -> "_SweepBar":
        if self.progress is not None:
            self.progress.start()
        return self

    def __exit__(self, *exc: object) -> None:
        if self.progress is not None:
            self.progress.stop()

    def __call__(self, done: int, failed: int, running: int, total: int,
                 dashboard: str | None) -> None:
        if self.progress is None:
            return
        if dashboard and not self.shown_dashboard:
            self.progress.console.print(f"dashboard: {dashboard}", highlight=False)
            self.shown_dashboard = True
        text = f"failed {failed}, running {running}"
        if self.task is None:
            self.task = self.progress.add_task(text, total=total)
        self.progress.update(self.task, completed=done, description=text)


def register(app: typer.Typer) -> None:
    """Add the ``sweep`` command to the command line ``app``."""
    from ..cli import DEBUG_OPT, QUIET_OPT, _consoles, _escape, _reported_errors, _table

    @app.command("sweep")
    def sweep_command(
            sweep_file: Path = typer.Argument(..., metavar="SWEEP.toml", show_default=False,
                                              help="Sweep file (TOML), see docs/sweep.md."),
            outdir: Path = typer.Option(..., "-o", "--outdir",
                                        help="Output folder; cases already stored there are "
                                             "not run again."),
            workers: Optional[int] = typer.Option(
                None, "--workers", help="Worker processes of the local cluster. "
                                        "[default: one per core]"),
            scheduler: Optional[str] = typer.Option(
                None, "--scheduler", help="A running Dask scheduler instead of a local "
                                          "cluster: its address (tcp://host:port) or its "
                                          "--scheduler-file."),
            memory_limit: Optional[str] = typer.Option(
                None, "--memory-limit", help="Memory limit of each local worker, e.g. 2GiB. "
                                             "[default: the memory shared among the workers]"),
            quiet: bool = QUIET_OPT, debug: bool = DEBUG_OPT) -> None:
        """Run a design study: every case of a sweep file on Dask, tables and report in OUT."""
        from .run import sweep
        from .store import stored_cases

        out, err = _consoles()
        with _reported_errors(debug):
            try:
                with _SweepBar(err, enabled=not quiet) as bar:
                    result = sweep(sweep_file, outdir, workers=workers, scheduler=scheduler,
                                   memory_limit=memory_limit, progress=bar)
            except KeyboardInterrupt:
                stored = len(stored_cases(outdir))
                err.print(f"interrupted: {stored} case results are stored in "
                          f"{_escape(str(outdir))}; run the same command again to compute "
                          "the others", highlight=False, soft_wrap=True)
                raise typer.Exit(EXIT_INTERRUPTED) from None
        if not quiet:
            rows = [("cases", f"{len(result.rows)} (ok {len(result.rows) - result.failed}, "
                              f"failed {result.failed})"),
                    ("this run", f"{result.computed} cases computed on {result.models} "
                                 f"models, {result.reused} read back"),
                    ("workers", str(result.workers) if result.computed else
                     "none started (every case was stored)"),
                    ("wall time", f"{result.wall_s:.1f} s"),
                    *((name, str(path)) for name, path in result.files.items()
                      if not name.startswith("plot"))]
            out.print(_table(f"splinedeform sweep: {result.sweep.title or sweep_file.name}",
                             rows))
