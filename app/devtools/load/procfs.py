"""What the kernel says about a process: CPU time, resident memory, threads (``/proc/<pid>``).

Read from outside the process, so measuring costs the measured process nothing. Linux only,
like the tool.
"""

from __future__ import annotations

import dataclasses
import os
import threading
import time

_TICKS = os.sysconf("SC_CLK_TCK")


@dataclasses.dataclass(frozen=True)
class Usage:
    """One look at a process."""

    at: float  # time.monotonic()
    cpu_seconds: float  # user + system since the process started
    rss_bytes: int
    threads: int


def usage(pid: int) -> Usage:
    """The process's CPU time, resident set and thread count now (OSError once it is gone)."""
    at = time.monotonic()
    with open(f"/proc/{pid}/stat") as f:
        stat = f.read()
    # The command name is in parentheses and may hold spaces: count fields after its end.
    fields = stat[stat.rindex(")") + 2 :].split()
    cpu = (int(fields[11]) + int(fields[12])) / _TICKS  # utime, stime (fields 14 and 15)
    rss = 0
    with open(f"/proc/{pid}/status") as f:
        for line in f:
            if line.startswith("VmRSS:"):
                rss = int(line.split()[1]) * 1024
                break
    threads = len(os.listdir(f"/proc/{pid}/task"))
    return Usage(at, cpu, rss, threads)


def cpu_percent(first: Usage, last: Usage) -> float:
    """Mean CPU use between two looks, in % of one core."""
    elapsed = last.at - first.at
    return 100.0 * (last.cpu_seconds - first.cpu_seconds) / elapsed if elapsed > 0 else 0.0


def combined(series: list[list[Usage]]) -> list[Usage]:
    """Several processes looked at together (a server and its workers) as one: at each look,
    their CPU times, memory and threads summed."""
    return [
        Usage(
            looks[0].at,
            sum(u.cpu_seconds for u in looks),
            sum(u.rss_bytes for u in looks),
            sum(u.threads for u in looks),
        )
        for looks in zip(*series, strict=False)
    ]


@dataclasses.dataclass(frozen=True)
class Machine:
    """The whole machine's CPU time so far, from ``/proc/stat`` (clock ticks)."""

    busy: int
    total: int

    @staticmethod
    def now() -> Machine:
        with open("/proc/stat") as f:
            ticks = [int(x) for x in f.readline().split()[1:9]]  # user .. steal
        idle = ticks[3] + ticks[4]  # idle, iowait
        return Machine(sum(ticks) - idle, sum(ticks))

    def busy_since(self, earlier: Machine) -> float:
        """The fraction of all cores' time that was busy between two looks."""
        total = self.total - earlier.total
        return (self.busy - earlier.busy) / total if total > 0 else 0.0


class Sampler:
    """Looks at some processes every ``interval`` seconds in a thread, until :meth:`stop` (or
    ``max_samples`` looks, so that it always ends)."""

    def __init__(self, pids: dict[str, int], interval: float, max_samples: int = 100_000):
        self.pids = dict(pids)
        self.interval = float(interval)
        self.max_samples = max_samples
        self.samples: dict[str, list[Usage]] = {name: [] for name in pids}
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name="load-sampler", daemon=True)

    def __enter__(self) -> Sampler:
        self._look()
        self._thread.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self.stop()

    def stop(self) -> None:
        if self._thread.is_alive():
            self._stop.set()
            self._thread.join(self.interval + 5.0)
            self._look()

    def _look(self) -> None:
        for name, pid in self.pids.items():
            try:
                self.samples[name].append(usage(pid))
            except OSError:  # gone: the phase notices through its pipe
                pass

    def _run(self) -> None:
        for _ in range(self.max_samples):
            if self._stop.wait(self.interval):
                return
            self._look()

    def cpu_percents(self, name: str) -> list[float]:
        """CPU use over each interval, in % of one core."""
        s = self.samples[name]
        return [cpu_percent(a, b) for a, b in zip(s, s[1:], strict=False)]
