"""The progress of a report run on stderr, drawn by rich: a bar on an interactive terminal, a few
plain lines (one per tenth of the run) when stderr is a file, a pipe or a CI log."""

from __future__ import annotations

from rich.console import Console
from rich.progress import BarColumn, TaskProgressColumn, TextColumn, TimeElapsedColumn
from rich.progress import Progress as RichProgress

__all__ = ["PLAIN_STEPS", "Progress"]

#: Lines written when stderr is not a terminal: one at each tenth of the run, and the last.
PLAIN_STEPS = 10


class Progress:
    """``advance`` the run by units of work, ``show`` what runs now, ``close`` at the end.

    ``console`` is where it goes (stderr by default); ``enabled=False`` writes nothing.
    """

    def __init__(self, total: int, enabled: bool = True, console: Console | None = None) -> None:
        self.total = max(total, 1)
        self.done = 0
        self.enabled = enabled
        self.console = console if console is not None else Console(stderr=True)
        self._step = 0  # plain lines: the last tenth written
        self._bar: RichProgress | None = None
        if enabled and self.console.is_interactive:
            self._bar = RichProgress(
                TextColumn("[progress.description]{task.description:<48}"),
                BarColumn(),
                TaskProgressColumn(),
                TimeElapsedColumn(),
                console=self.console,
                transient=False,
            )
            self._task = self._bar.add_task("", total=self.total)
            self._bar.start()

    def advance(self, label: str, units: int = 1) -> None:
        self.done = min(self.done + units, self.total)
        self.show(label)

    def show(self, label: str) -> None:
        if not self.enabled:
            return
        if self._bar is not None:
            self._bar.update(self._task, completed=self.done, description=label[:48])
            return
        step = PLAIN_STEPS * self.done // self.total
        if step > self._step:
            self._step = step
            percent = 100 * self.done // self.total
            self.console.print(f"report: {percent:3d}%  {label}", markup=False, highlight=False)

    def close(self) -> None:
        if not self.enabled:
            return
        self.done = self.total
        if self._bar is not None:
            self._bar.update(self._task, completed=self.total, description="done")
            self._bar.stop()
        elif self._step < PLAIN_STEPS:
            self._step = PLAIN_STEPS
            self.console.print("report: 100%  done", markup=False, highlight=False)
