"""Progress bars for the command line: one rich bar per pipeline stage.

:class:`StageProgress` is the ``progress(stage, done, total)`` callback that
:func:`splinedeform.scenario.run` expects; a quiet instance does nothing.
"""

from __future__ import annotations

from types import TracebackType
from typing import Any


class StageProgress:
    """Rich progress display with one task per stage (``build``, ``solve``, ``frames``, …).

    Parameters
    ----------
    console : rich.console.Console
        Where to draw (the command line uses stderr, so stdout holds only the summary).
    enabled : bool
        ``False`` (``--quiet``) draws nothing.
    """

    def __init__(self, console: Any, enabled: bool = True) -> None:
        self.enabled = enabled
        self.tasks: dict[str, Any] = {}
        self._progress: Any = None
        if enabled:
            from rich.progress import (BarColumn, MofNCompleteColumn, Progress, SpinnerColumn,
                                       TextColumn, TimeElapsedColumn)

            self._progress = Progress(SpinnerColumn(), TextColumn("{task.description:<18}"),
                                      BarColumn(), MofNCompleteColumn(), TimeElapsedColumn(),
                                      console=console, transient=False)

    def __enter__(self) -> StageProgress:
        if self._progress is not None:
            self._progress.start()
        return self

    def __exit__(self, exc_type: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> None:
        if self._progress is not None:
            self._progress.stop()

    def __call__(self, stage: str, done: int, total: int) -> None:
        """Show ``done`` of ``total`` steps of ``stage`` (a new stage gets a new bar)."""
        if self._progress is None:
            return
        if stage not in self.tasks:
            self.tasks[stage] = self._progress.add_task(stage, total=max(total, 1))
        self._progress.update(self.tasks[stage], completed=done, total=max(total, 1))
