"""Scene-node internals of viser 1.1.x: part of the one adapter to viser's private names
(:mod:`poinsot.app.viser_private`, whose docstring has the inventory).

- :func:`node_state`: a handle's server-side state (``handle._impl``: ``name``, ``wxyz``,
  ``position``, ``props``, ``removed``, ``api``);
- :func:`queue_orientation`, :func:`queue_position`, :func:`queue_props`: the message a
  setter queues (:func:`orientation_message`, :func:`position_message`,
  :func:`props_message`), put on the scene API's queue (``SceneApi._queue_scene_message``)
  without the setter's comparison;
- :func:`cache_property_hints`: ``AssignablePropsBase._prop_hints`` (a per-instance
  ``functools.cached_property``) replaced by a property cached per properties class.
"""

from __future__ import annotations

import functools
import typing
from typing import Any

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


def cache_property_hints() -> None:
    """Make viser look a handle's property type hints up once per properties class, not once
    per handle (viser only reads them). Idempotent."""
    base: Any = _assignable_props_api.AssignablePropsBase
    base._prop_hints = CACHED_HINTS
