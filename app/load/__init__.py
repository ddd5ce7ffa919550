"""Load test of the live server: ``python -m poinsot.app.load`` (``make load``).

It measures the server as it is, on this machine's loopback only, with a server child process
of its own (:mod:`~poinsot.app.load.server_process`) and clients in other processes, so that
the clients' decoding is not server time:

- soak (:func:`~poinsot.app.load.phases.soak`), storm (:mod:`~poinsot.app.load.storm`), stall
  and flood (:mod:`~poinsot.app.load.flood`), hostile (:mod:`~poinsot.app.load.hostile`, the
  inputs in :mod:`~poinsot.app.load.crafted`), each with a fresh server;
- the clients: :mod:`~poinsot.app.load.fleet` (decoding probes),
  :mod:`~poinsot.app.load.raw` (a bare-socket websocket that misbehaves on purpose);
- what the kernel says about a process: :mod:`~poinsot.app.load.procfs`;
- figures, goals and the table: :mod:`~poinsot.app.load.figures`;
- the command line: :mod:`~poinsot.app.load.cli`.

Every loop is bounded in count and in time, and every child process stops by itself.
"""

from poinsot.app.load.cli import main, run
from poinsot.app.load.config import Config, Report
from poinsot.app.load.figures import Bounds, Figure, exit_status, format_table
from poinsot.app.load.phases import PHASES

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
