"""Cheap writes to existing scene nodes, for what changes on every frame.

viser's setters (``handle.wxyz = q``, ``handle.position = p``, ``handle.points = a``) cast the
value, compare it with the last one (``np.allclose`` for a pose, ``np.array_equal`` for an
array), then store it and queue the update. On this machine that is 50-80 us per pose and
about 35 us per array, more than the rest of a frame's own work together, and the comparison
buys nothing on the frame path: a moving body's values are new every frame. These functions
store the same server-side state and queue the same message as the setters, without the
comparison and with one copy:

- :func:`set_wxyz` and :func:`set_position`: a node's pose (``SetOrientationMessage``,
  ``SetPositionMessage``);
- :func:`set_points`: a line-segments or arrows node's ``points`` (``SceneNodeUpdateMessage``).

Making a node costs viser 0.3-0.5 ms, most of it ``typing.get_type_hints`` on the node's
properties class, looked up anew for every handle (a ``functools.cached_property`` of the
instance, whose first computation also takes a lock shared by every handle). The hints depend
on the class alone: :func:`cache_property_hints` (run when this module is imported) keeps them
per class, and a trail's new chunk or a label costs a third.

They use viser 1.1's handle internals (the handle's ``_impl`` and its scene API's
``_queue_scene_message``), reached through the adapter :mod:`poinsot.app.viser_private.scene`
(where ``tests/app/test_viser_private.py`` pins them). ``tests/app/test_updates.py`` checks that
each one leaves the handle and the queued message exactly as the public setter does, so a viser
upgrade that changes those internals fails a test instead of a frame. A write to a removed
node raises as the setter does. Values that only a setter should see (the first pose, a
colour, a style) keep using the setters.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import viser

from poinsot.app import viser_private as private


def _impl(handle: viser.SceneNodeHandle) -> Any:
    impl = private.node_state(handle)
    if impl.removed:
        raise RuntimeError(f"Cannot update the removed scene node {impl.name!r}.")
    return impl


def set_wxyz(handle: viser.SceneNodeHandle, wxyz: np.ndarray) -> None:
    """Set the node's orientation (unit quaternion w, x, y, z), shape (4,)."""
    impl = _impl(handle)
    value = (float(wxyz[0]), float(wxyz[1]), float(wxyz[2]), float(wxyz[3]))
    impl.wxyz[:] = value
    private.queue_orientation(impl, value)


def set_position(handle: viser.SceneNodeHandle, position: np.ndarray) -> None:
    """Set the node's position in its parent's frame, shape (3,)."""
    impl = _impl(handle)
    value = (float(position[0]), float(position[1]), float(position[2]))
    impl.position[:] = value
    private.queue_position(impl, value)


def set_points(handle: viser.LineSegmentsHandle | viser.ArrowsHandle, points: np.ndarray) -> None:
    """Set a line-segments or arrows node's segments, shape (N, 2, 3) (cast to float32)."""
    impl = _impl(handle)
    value = np.array(points, dtype=np.float32)  # the message's own copy
    stored = impl.props.points
    if stored.shape == value.shape:
        stored[...] = value
    else:
        impl.props.points = value.copy()
    private.queue_props(impl, {"points": value})


#: Kept here for the callers that name it; the patch itself is the adapter's.
cache_property_hints = private.cache_property_hints

cache_property_hints()
