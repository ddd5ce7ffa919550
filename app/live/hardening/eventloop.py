"""A serving process's event loop: libuv's (``uvloop``), not asyncio's own selector loop.

viser runs every browser's websocket of a process on one asyncio loop (its server's thread),
and in a lecture hall most of a worker's work is that loop's: each frame of the followers'
poses is a write on each follower's socket (:mod:`..classroom.cast`), and each browser's own
windows are sent by a task of its own. libuv's loop does a write, a callback and a wake-up in C
where asyncio's does them in Python. Measured with 300 followers on two workers, the moves
held (``docs/measurements/classroom.md``, "A move held"): the slowest follower at 17.8 to
20.5 fps while the lead moves (14.4 and 15.9 on asyncio's loop), the lead's move on every
follower at p95 0.97 to 1.2 s (1.7 and 2.2 s).

The choice is the process's (asyncio's event loop policy): only a process that serves and
nothing else sets it (``poinsot serve`` and its workers, the load test's servers), before
viser makes its loop. A test's process keeps asyncio's loop for its servers and for its
browser driver's own loop.
"""

from __future__ import annotations

import asyncio

import uvloop


def serve_on_libuv() -> None:
    """Make the event loops this process creates from now on libuv's (viser creates its own
    when its server starts). Idempotent."""
    if not isinstance(asyncio.get_event_loop_policy(), uvloop.EventLoopPolicy):
        asyncio.set_event_loop_policy(uvloop.EventLoopPolicy())


def on_libuv(loop: asyncio.AbstractEventLoop) -> bool:
    """Whether ``loop`` is libuv's."""
    return isinstance(loop, uvloop.Loop)
