"""Load test of the live server: ``python -m poinsot.app.devtools.load`` (``make load``).

It measures the server as it is, on this machine's loopback only, with a server child process
of its own (:mod:`~poinsot.app.devtools.load.server_process`) and clients in other processes, so
that the clients' decoding is not server time:

- soak (:func:`~poinsot.app.devtools.load.phases.soak`), storm
(:mod:`~poinsot.app.devtools.load.workloads.storm`), stall
  and flood (:mod:`~poinsot.app.devtools.load.workloads.flood`), hostile
  (:mod:`~poinsot.app.devtools.load.workloads.hostile`, the inputs in
  :mod:`~poinsot.app.devtools.load.crafted`), each with a fresh server;
- the clients: :mod:`~poinsot.app.devtools.load.fleet` (decoding probes),
  :mod:`~poinsot.app.devtools.load.raw` (a bare-socket websocket that misbehaves on purpose);
- what the kernel says about a process: :mod:`~poinsot.app.devtools.load.procfs`;
- figures, goals and the table: :mod:`~poinsot.app.devtools.load.figures`;
- the command line: :mod:`~poinsot.app.devtools.load.cli`.

Every loop is bounded in count and in time, and every child process stops by itself.
"""

from poinsot.app.devtools.load.cli import main, run
from poinsot.app.devtools.load.config import Config, Report
from poinsot.app.devtools.load.figures import Bounds, Figure, exit_status, format_table
from poinsot.app.devtools.load.phases import PHASES

__all__ = [
    "PHASES",
    "Bounds",
    "Config",
    "Figure",
    "Report",
    "exit_status",
    "format_table",
    "main",
    "run",
]
