"""A serving process's event loop: libuv's (``uvloop``), not asyncio's own selector loop.

viser runs every browser's websocket of a process on one asyncio loop (its server's thread),
and in a lecture hall most of a worker's work is that loop's: each frame of the followers'
poses is a write on each follower's socket (:mod:`..classroom.cast`), and each browser's own
windows are sent by a task of its own. libuv's loop does a write, a callback and a wake-up in C
where asyncio's does them in Python. Measured with 300 followers on two workers, the moves
held (``docs/measurements/classroom.md``, "A move held"): the slowest follower at 17.8 to
20.5 fps while the lead moves (14.4 and 15.9 on asyncio's loop), the lead's move on every
follower at p95 0.97 to 1.2 s (1.7 and 2.2 s).

Only a server that serves a process and nothing else asks for it (``poinsot serve`` and its
workers, the load test's servers: ``PoinsotApp(serving=True)``), and only while viser makes
its loop (:func:`libuv_loops`: asyncio's policy is the process's, and viser's constructor
waits until its loop runs): every other loop of the process (a test's servers, its browser
driver's) stays asyncio's.
"""

from __future__ import annotations

import asyncio
import contextlib
from collections.abc import Iterator

import uvloop


@contextlib.contextmanager
def libuv_loops() -> Iterator[None]:
    """The event loops made within are libuv's (viser makes its server's while it starts);
    the process's policy is asyncio's again after."""
    before = asyncio.get_event_loop_policy()
    asyncio.set_event_loop_policy(uvloop.EventLoopPolicy())
    try:
        yield
    finally:
        asyncio.set_event_loop_policy(before)
