"""A follower's rebuild on the server, building the lead's body itself or taking its worker's
shared motion (:mod:`poinsot.app.construction.sampled.motion`): ``python -m
poinsot.app.devtools.load.workloads.follow_rebuild``.

One served app and one probe; on the session's own thread, ``--rebuilds`` times each: a body
built by the session itself (as every follower did before the shared motion), and the same kind
of body taken from the process's :class:`~poinsot.app.construction.sampled.motion.MotionCache`,
built and shown once beforehand (what the first follower of a worker pays, not timed). The figure is
the thread's CPU time (:func:`time.thread_time`), which the other work of a busy machine does not
inflate; viser's own encoding, on its event loop, is not in it (the same for both).
"""

from __future__ import annotations

import argparse
import functools
import statistics
import threading
import time

from poinsot.app.devtools.probe import Probe
from poinsot.app.live.panel import readouts
from poinsot.app.live.server import PoinsotApp
from poinsot.app.live.session.session import Session
from poinsot.app.model.parameters import drawn_solid


def _measure(session: Session, rebuilds: int) -> tuple[list[float], list[float]]:
    """(own, shared) thread CPU seconds per rebuild (the session's thread)."""
    build = session.build
    base = build.desired
    own: list[float] = []
    shared: list[float] = []
    for i in range(rebuilds):
        session.follow.mode = "own"
        build.desired = base.with_D(2.05 + 0.002 * i)
        start = time.thread_time()
        build.rebuild(session.showcase)
        own.append(time.thread_time() - start)
        params = base.with_D(2.25 + 0.002 * i)
        session.follow.mode = "follow"
        solid = drawn_solid(params.inertia, build.base, build.base_inertia)
        motion = build.shared_motion(params, solid)
        assert motion is not None
        motion.geometry.polhode_segments()  # what the first follower's view makes once
        motion.memo("readouts", functools.partial(readouts.markdown, motion.body))
        build.desired = params
        start = time.thread_time()
        build.rebuild(session.showcase)
        shared.append(time.thread_time() - start)
    session.follow.mode = "own"
    return own, shared


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rebuilds", type=int, default=40, help="rebuilds of each kind")
    args = parser.parse_args(argv)
    app = PoinsotApp("127.0.0.1", 0)
    probe = Probe(app.port)
    try:
        if not probe.wait_for(lambda p: p.has_widget("Explore from here"), 60):
            raise SystemExit("the page never received its panel")
        session = app.wait_for_sessions(1, 30)[0]
        result: list[tuple[list[float], list[float]]] = []
        done = threading.Event()

        def run() -> None:
            result.append(_measure(session, args.rebuilds))
            done.set()

        session.post(run)
        if not done.wait(600):
            raise SystemExit("the rebuilds did not end within 10 minutes")
        own, shared = result[0]
        ms = [1e3 * statistics.median(v) for v in (own, shared)]
        print(
            f"a follower's rebuild, thread CPU, median of {args.rebuilds}: building the lead's "
            f"body itself {ms[0]:.2f} ms; from the worker's shared motion {ms[1]:.2f} ms"
        )
    finally:
        probe.close()
        app.stop()


if __name__ == "__main__":
    main()
