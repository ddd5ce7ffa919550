"""Run a command beside busy loops: the suite on a machine that something else keeps busy, as a
student's laptop or a shared CI runner is (``make test-busy`` runs ``make test`` so).

    python tests/busy.py [--loops N] -- COMMAND [ARG...]

Starts ``N`` (2 unless told) Python processes that spin (``while True: pass``), runs
``COMMAND``, and stops the loops however the command ends (its failure, Ctrl-C at the terminal,
a SIGTERM to this script); exits with the command's status.
"""

from __future__ import annotations

import argparse
import os
import signal
import subprocess
import sys

#: A loop that spins until killed; Ctrl-C at the terminal ends it quietly too (no traceback).
SPIN = "import signal; signal.signal(signal.SIGINT, signal.SIG_DFL)\nwhile True: pass"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--loops", type=int, default=2, help="busy loops beside it (2)")
    parser.add_argument("command", nargs=argparse.REMAINDER, help="-- COMMAND [ARG...]")
    args = parser.parse_args(argv)
    command = args.command[1:] if args.command[:1] == ["--"] else args.command
    if not command:
        parser.error("no command given (python tests/busy.py -- make test)")
    loops = [subprocess.Popen([sys.executable, "-c", SPIN]) for _ in range(args.loops)]
    print(f"busy.py: {len(loops)} busy loops beside {' '.join(command)}", flush=True)
    try:
        return run(command)
    finally:
        for loop in loops:
            loop.kill()
        for loop in loops:
            loop.wait()
        print(f"busy.py: the {len(loops)} busy loops stopped", flush=True)


def run(command: list[str]) -> int:
    """``command``'s status (128 + the signal's number if one ended it), once it has ended.
    It runs in a process group of its own: Ctrl-C or a SIGTERM sent to this script is passed
    on to the whole group (make, pytest and its workers), not to make alone."""
    child = subprocess.Popen(command, start_new_session=True)

    def pass_on(signum: int, _frame: object) -> None:
        if child.poll() is None:
            os.killpg(child.pid, signum)

    signal.signal(signal.SIGINT, pass_on)
    signal.signal(signal.SIGTERM, pass_on)
    status = child.wait()
    return 128 - status if status < 0 else status  # killed by a signal: as a shell says it


if __name__ == "__main__":
    sys.exit(main())
