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
``_queue_scene_message``), kept in this one module. ``tests/app/test_updates.py`` checks that
each one leaves the handle and the queued message exactly as the public setter does, so a viser
upgrade that changes those internals fails a test instead of a frame. A write to a removed
node raises as the setter does. Values that only a setter should see (the first pose, a
colour, a style) keep using the setters.
"""

from __future__ import annotations

import functools
import typing
from typing import Any

import numpy as np
import viser
from viser import _assignable_props_api, _messages


def _impl(handle: viser.SceneNodeHandle) -> Any:
    impl = handle._impl
    if impl.removed:
        raise RuntimeError(f"Cannot update the removed scene node {impl.name!r}.")
    return impl


def set_wxyz(handle: viser.SceneNodeHandle, wxyz: np.ndarray) -> None:
    """Set the node's orientation (unit quaternion w, x, y, z), shape (4,)."""
    impl = _impl(handle)
    value = (float(wxyz[0]), float(wxyz[1]), float(wxyz[2]), float(wxyz[3]))
    impl.wxyz[:] = value
    impl.api._queue_scene_message(_messages.SetOrientationMessage(impl.name, value))


def set_position(handle: viser.SceneNodeHandle, position: np.ndarray) -> None:
    """Set the node's position in its parent's frame, shape (3,)."""
    impl = _impl(handle)
    value = (float(position[0]), float(position[1]), float(position[2]))
    impl.position[:] = value
    impl.api._queue_scene_message(_messages.SetPositionMessage(impl.name, value))


def set_points(handle: viser.LineSegmentsHandle | viser.ArrowsHandle, points: np.ndarray) -> None:
    """Set a line-segments or arrows node's segments, shape (N, 2, 3) (cast to float32)."""
    impl = _impl(handle)
    value = np.array(points, dtype=np.float32)  # the message's own copy
    stored = impl.props.points
    if stored.shape == value.shape:
        stored[...] = value
    else:
        impl.props.points = value.copy()
    impl.api._queue_scene_message(_messages.SceneNodeUpdateMessage(impl.name, {"points": value}))


@functools.cache
def _hints(props_class: Any) -> dict[str, Any]:
    return typing.get_type_hints(props_class)


def cache_property_hints() -> None:
    """Make viser look a handle's property type hints up once per properties class, not once
    per handle (viser only reads them). Idempotent."""
    base: Any = _assignable_props_api.AssignablePropsBase
    base._prop_hints = property(_prop_hints)  # a plain property: no per-instance lock either


def _prop_hints(handle: Any) -> dict[str, Any]:
    props_class: Any = type(handle._impl.props)
    return _hints(props_class)


cache_property_hints()
