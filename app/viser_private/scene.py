"""Scene-node internals of viser 1.1.x: part of the one adapter to viser's private names
(:mod:`poinsot.app.viser_private`, whose docstring has the inventory).

- :func:`node_state`: a handle's server-side state (``handle._impl``: ``name``, ``wxyz``,
  ``position``, ``props``, ``removed``, ``api``);
- :func:`queue_orientation`, :func:`queue_position`, :func:`queue_props`: the message a
  setter queues (:func:`orientation_message`, :func:`position_message`,
  :func:`props_message`), put on the scene API's queue (``SceneApi._queue_scene_message``)
  without the setter's comparison;
- :func:`cache_property_hints`: ``AssignablePropsBase._prop_hints`` (a per-instance
  ``functools.cached_property``) replaced by a property cached per properties class, and
  ``AssignablePropsBase._cast_value_recursive`` (a property's value cast to its hint before it
  is compared and sent) by :func:`cast_value`, the same cast without building four ``numpy``
  array aliases per value and per element of a tuple (about 3 microseconds each: a body's
  rebuild sets a dozen properties, 0.3 ms of its 1 ms).
"""

from __future__ import annotations

import functools
import typing
from typing import Any

import numpy as np
import numpy.typing as npt
import viser
from viser import _assignable_props_api, _messages

#: The attributes of a handle's ``_impl`` that the fast setters read and write.
NODE_FIELDS = ("name", "wxyz", "position", "props", "removed", "api")


def node_state(handle: viser.SceneNodeHandle) -> Any:
    """The server-side state of a scene node (viser 1.1: ``handle._impl``)."""
    return handle._impl


def orientation_message(name: str, wxyz: tuple[float, float, float, float]) -> Any:
    """The message ``handle.wxyz = wxyz`` queues for the node ``name``."""
    return _messages.SetOrientationMessage(name, wxyz)


def position_message(name: str, position: tuple[float, float, float]) -> Any:
    """The message ``handle.position = position`` queues for the node ``name``."""
    return _messages.SetPositionMessage(name, position)


def props_message(name: str, updates: dict[str, Any]) -> Any:
    """The message setting the properties ``updates`` on the node ``name`` queues."""
    return _messages.SceneNodeUpdateMessage(name, updates)


def queue_orientation(node: Any, wxyz: tuple[float, float, float, float]) -> None:
    """Queue the message that ``handle.wxyz = wxyz`` queues (``node``: :func:`node_state`)."""
    node.api._queue_scene_message(orientation_message(node.name, wxyz))


def queue_position(node: Any, position: tuple[float, float, float]) -> None:
    """Queue the message that ``handle.position = position`` queues."""
    node.api._queue_scene_message(position_message(node.name, position))


def queue_props(node: Any, updates: dict[str, Any]) -> None:
    """Queue the message that setting the properties ``updates`` on the handle queues."""
    node.api._queue_scene_message(props_message(node.name, updates))


@functools.cache
def _hints(props_class: Any) -> dict[str, Any]:
    return typing.get_type_hints(props_class)


def _prop_hints(handle: Any) -> dict[str, Any]:
    props_class: Any = type(handle._impl.props)
    return _hints(props_class)


#: What :func:`cache_property_hints` puts on ``AssignablePropsBase._prop_hints``.
CACHED_HINTS = property(_prop_hints)  # a plain property: no per-instance lock either

#: viser's own cast, kept for the test that compares :func:`cast_value` with it.
VISER_CAST = _assignable_props_api.AssignablePropsBase._cast_value_recursive

#: The array hints viser's cast converts a value to, made once (their ``dtype``; ``uint8``:
#: a colour's, converted only for a property named for a colour).
_ARRAY_HINTS: dict[Any, Any] = {
    npt.NDArray[np.float16]: np.float16,
    npt.NDArray[np.float32]: np.float32,
    npt.NDArray[np.float64]: np.float64,
    npt.NDArray[np.uint8]: np.uint8,
}


def cast_value(self: Any, hint: Any, value: Any, prop_name: str) -> Any:
    """``AssignablePropsBase._cast_value_recursive`` of viser 1.1, the same branches in the
    same order, its array hints looked up rather than built anew for each comparison."""
    try:
        dtype = _ARRAY_HINTS.get(hint)
    except TypeError:  # an unhashable hint is none of them
        dtype = None
    if dtype is np.uint8:
        if "color" in prop_name:
            return _assignable_props_api.colors_to_uint8(value)
    elif dtype is not None:
        return np.asarray(value).astype(dtype)
    if isinstance(value, np.ndarray):
        return value
    args = getattr(hint, "__args__", None)
    if (
        isinstance(value, tuple)
        and getattr(hint, "__origin__", None) is tuple
        and args is not None
        and len(args) == 2
        and args[1] is ...
    ):
        return tuple(cast_value(self, args[0], item, prop_name) for item in value)
    return value


def cache_property_hints() -> None:
    """Make viser look a handle's property type hints up once per properties class, not once
    per handle (viser only reads them), and cast a value to its hint with :func:`cast_value`.
    Idempotent."""
    base: Any = _assignable_props_api.AssignablePropsBase
    base._prop_hints = CACHED_HINTS
    base._cast_value_recursive = cast_value
