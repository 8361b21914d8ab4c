"""Progress for the command line: one rich bar per pipeline stage, simulated time in a solve.

:class:`StageProgress` is the ``progress(stage, done, total)`` callback that
:func:`splinedeform.scenario.run` expects; a quiet instance does nothing. The numerical
integrators report how far they have stepped through :func:`simulated_time`; a caller that
wants to see it installs a receiver with :func:`reporting_simulated_time` (nothing is
reported otherwise), and :meth:`StageProgress.simulated` shows it as ``t = … of t_end``
with the time left, estimated from the recent rate ``Δt_simulated / Δt_wall``.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from types import TracebackType
from typing import Any

#: ``receiver(t, t_end)``: the simulated time ``t`` an integrator has reached
SimulatedTime = Callable[[float, float], None]

_RECEIVER: ContextVar[SimulatedTime | None] = ContextVar("splinedeform_simulated_time",
                                                         default=None)

#: shortest wall-clock interval between two redraws of the simulated time (seconds)
REDRAW = 0.1


def simulated_time(t: float, t_end: float) -> None:
    """Report that an integrator has reached simulated time ``t`` of ``[0, t_end]``.

    Costs one context-variable lookup when nobody listens.
    """
    receiver = _RECEIVER.get()
    if receiver is not None:
        receiver(float(t), float(t_end))


@contextmanager
def reporting_simulated_time(receiver: SimulatedTime | None) -> Iterator[None]:
    """Send the :func:`simulated_time` reports made inside the block to ``receiver``."""
    token = _RECEIVER.set(receiver)
    try:
        yield
    finally:
        _RECEIVER.reset(token)


def _columns() -> list[Any]:
    from rich.progress import BarColumn, ProgressColumn, SpinnerColumn, TextColumn
    from rich.progress import TimeElapsedColumn
    from rich.text import Text

    class Count(ProgressColumn):
        """``done/total`` steps, or ``t = 2.5 of 10`` for a stage that reports simulated
        time."""

        def render(self, task: Any) -> Text:
            if task.fields.get("simulated"):
                return Text(f"t = {task.completed:.4g} of {task.total:.4g}",
                            style="progress.download")
            return Text(f"{int(task.completed)}/{int(task.total or 0)}",
                        style="progress.download")

    class Left(ProgressColumn):
        """Time left of a stage that reports simulated time (blank for the others)."""

        def render(self, task: Any) -> Text:
            if not task.fields.get("simulated") or task.finished:
                return Text("")
            left = task.time_remaining
            if left is None:
                return Text("-:--:-- left", style="progress.remaining")
            minutes, seconds = divmod(int(round(left)), 60)
            hours, minutes = divmod(minutes, 60)
            return Text(f"{hours}:{minutes:02d}:{seconds:02d} left", style="progress.remaining")

    return [SpinnerColumn(), TextColumn("{task.description:<18}"), BarColumn(), Count(),
            TimeElapsedColumn(), Left()]


class StageProgress:
    """Rich progress display with one task per stage (``build``, ``solve``, ``frames``, …).

    Parameters
    ----------
    console : rich.console.Console
        Where to draw (the command line uses stderr, so stdout holds only the summary).
    enabled : bool
        ``False`` (``--quiet``) draws nothing.
    clock : callable, optional
        Wall clock in seconds (default :func:`time.monotonic`), for the time left.
    """

    def __init__(self, console: Any, enabled: bool = True,
                 clock: Callable[[], float] = time.monotonic) -> None:
        self.enabled = enabled
        self.tasks: dict[str, Any] = {}
        self._progress: Any = None
        self._clock = clock
        self._drawn = -float("inf")
        if enabled:
            from rich.progress import Progress

            self._progress = Progress(*_columns(), console=console, transient=False,
                                      get_time=clock)

    def __enter__(self) -> StageProgress:
        if self._progress is not None:
            self._progress.start()
        return self

    def __exit__(self, exc_type: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> None:
        if self._progress is not None:
            self._progress.stop()

    def _task(self, stage: str, total: float) -> Any:
        if stage not in self.tasks:
            self.tasks[stage] = self._progress.add_task(stage, total=total, simulated=False)
        return self.tasks[stage]

    def __call__(self, stage: str, done: int, total: int) -> None:
        """Show ``done`` of ``total`` steps of ``stage`` (a new stage gets a new bar)."""
        if self._progress is None:
            return
        task = self._task(stage, max(total, 1))
        if self._progress.tasks[task].fields.get("simulated"):     # keep t = … of t_end
            if done >= total:
                self._progress.update(task, completed=self._progress.tasks[task].total)
            return
        self._progress.update(task, completed=done, total=max(total, 1))

    def simulated(self, stage: str, t: float, t_end: float) -> None:
        """Show that the integrator of ``stage`` has reached simulated time ``t`` of
        ``t_end``; redrawn at most every :data:`REDRAW` seconds, and at the end.

        The time left is rich's estimate ``(t_end - t) / s`` with ``s`` the simulated
        seconds per wall-clock second over the last 30 s of reports.
        """
        if self._progress is None:
            return
        now = self._clock()
        if now - self._drawn < REDRAW and t < t_end:
            return
        self._drawn = now
        task = self._task(stage, t_end)
        shown = self._progress.tasks[task]
        reached = shown.completed if shown.fields.get("simulated") else 0.0
        # the solve_ivp methods try steps and step back: the bar shows the furthest time
        self._progress.update(task, completed=min(max(t, reached), t_end), total=t_end,
                              simulated=True)

    def receiver(self, stage: str) -> SimulatedTime:
        """The :func:`reporting_simulated_time` receiver that draws on the bar of ``stage``."""
        return lambda t, t_end: self.simulated(stage, t, t_end)
