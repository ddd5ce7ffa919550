"""The console progress bar of a report run (stderr, one line)."""

from __future__ import annotations

import sys
import time

__all__ = ["Progress"]


class Progress:
    """A one-line text bar on stderr: ``[#####.....]  45%  case / method setting``."""

    def __init__(self, total: int, enabled: bool = True, width: int = 30) -> None:
        self.total = max(total, 1)
        self.done = 0
        self.enabled = enabled
        self.width = width
        self.start = time.perf_counter()

    def advance(self, label: str, units: int = 1) -> None:
        self.done = min(self.done + units, self.total)
        self.show(label)

    def show(self, label: str) -> None:
        if not self.enabled:
            return
        filled = int(self.width * self.done / self.total)
        bar = "#" * filled + "." * (self.width - filled)
        elapsed = time.perf_counter() - self.start
        sys.stderr.write(
            f"\r[{bar}] {100 * self.done // self.total:3d}% {elapsed:6.1f}s  {label[:48]:<48}"
        )
        sys.stderr.flush()

    def close(self) -> None:
        if self.enabled:
            self.done = self.total
            self.show("done")
            sys.stderr.write("\n")
            sys.stderr.flush()
