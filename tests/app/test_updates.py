"""The frame path's cheap writes leave a node and its queued message exactly as viser's public
setters do (so a viser upgrade that changes the internals they use fails here)."""

from __future__ import annotations

from collections.abc import Callable, Iterator
from typing import Any

import numpy as np
import pytest
import viser

from poinsot.app import viser_private
from poinsot.app.construction import updates


@pytest.fixture(scope="module")
def server() -> Iterator[viser.ViserServer]:
    server = viser.ViserServer("127.0.0.1", 0, verbose=False)
    yield server
    server.stop()


def _recorded(
    monkeypatch: pytest.MonkeyPatch, server: viser.ViserServer, write: Callable[[], None]
) -> list[Any]:
    queued: list[Any] = []
    original = server.scene._queue_scene_message

    def record(message: Any) -> None:
        queued.append(message)
        original(message)

    with monkeypatch.context() as patch:
        patch.setattr(server.scene, "_queue_scene_message", record)
        write()
    return queued


def _same_message(a: Any, b: Any) -> None:
    assert type(a) is type(b)
    fields_a, fields_b = a.as_serializable_dict(), b.as_serializable_dict()
    assert fields_a.keys() == fields_b.keys()
    for key in fields_a:
        np.testing.assert_array_equal(np.asarray(fields_a[key]), np.asarray(fields_b[key]))


def _set(handle: Any, name: str, value: Any) -> Callable[[], None]:
    return lambda: setattr(handle, name, value)


@pytest.mark.parametrize(
    ("name", "fast", "value", "other"),
    [
        ("wxyz", updates.set_wxyz, np.array([0.5, 0.5, -0.5, 0.5]), np.array([1.0, 0, 0, 0])),
        ("position", updates.set_position, np.array([0.25, -1.5, 3.0]), np.zeros(3)),
    ],
)
def test_a_pose_write_matches_the_setter(
    monkeypatch: pytest.MonkeyPatch,
    server: viser.ViserServer,
    name: str,
    fast: Any,
    value: Any,
    other: Any,
) -> None:
    handle = server.scene.add_frame(f"/pose_{name}")
    (by_setter,) = _recorded(monkeypatch, server, _set(handle, name, value))
    state = np.array(getattr(handle, name))
    handle_value = getattr(handle, name)
    setattr(handle, name, other)
    (by_fast,) = _recorded(monkeypatch, server, lambda: fast(handle, value))
    _same_message(by_setter, by_fast)
    np.testing.assert_array_equal(getattr(handle, name), state)
    assert getattr(handle, name) is handle_value  # stored in place, as the setter does


@pytest.mark.parametrize("kind", ["line_segments", "arrows"])
@pytest.mark.parametrize("segments", [3, 5])
def test_a_points_write_matches_the_setter(
    monkeypatch: pytest.MonkeyPatch, server: viser.ViserServer, segments: int, kind: str
) -> None:
    add = getattr(server.scene, f"add_{kind}")
    handle = add(f"/{kind}_{segments}", np.zeros((3, 2, 3), np.float32), (255, 0, 0))
    value = np.random.default_rng(segments).normal(size=(segments, 2, 3))  # float64 in
    (by_setter,) = _recorded(monkeypatch, server, _set(handle, "points", value))
    state = handle.points.copy()
    handle.points = np.zeros((3, 2, 3), np.float32)
    (by_fast,) = _recorded(monkeypatch, server, lambda: updates.set_points(handle, value))
    _same_message(by_setter, by_fast)
    assert handle.points.dtype == np.float32
    np.testing.assert_array_equal(handle.points, state)
    # The queued array is the message's own: a later write does not change what was queued.
    sent = np.array(by_fast.updates["points"])
    updates.set_points(handle, value + 1.0)
    np.testing.assert_array_equal(by_fast.updates["points"], sent)


def test_a_write_to_a_removed_node_is_refused(server: viser.ViserServer) -> None:
    frame = server.scene.add_frame("/removed")
    lines = server.scene.add_line_segments("/removed_lines", np.zeros((1, 2, 3)), (0, 0, 0))
    frame.remove()
    lines.remove()
    with pytest.raises(RuntimeError, match="removed"):
        updates.set_wxyz(frame, np.array([1.0, 0.0, 0.0, 0.0]))
    with pytest.raises(RuntimeError, match="removed"):
        updates.set_position(frame, np.zeros(3))
    with pytest.raises(RuntimeError, match="removed"):
        updates.set_points(lines, np.zeros((1, 2, 3)))


def test_property_hints_are_looked_up_once_per_class(server: viser.ViserServer) -> None:
    """Handles of one kind share their properties' type hints, equal to what viser computes."""
    import typing

    from viser import _assignable_props_api

    base = _assignable_props_api.AssignablePropsBase
    assert base.__dict__["_prop_hints"] is viser_private.CACHED_HINTS
    a = server.scene.add_label("/hints_a", "a")
    b = server.scene.add_label("/hints_b", "b")
    lines = server.scene.add_line_segments("/hints_c", np.zeros((1, 2, 3)), (0, 0, 0))
    assert a._prop_hints is b._prop_hints
    assert a._prop_hints == typing.get_type_hints(type(a._impl.props))
    assert lines._prop_hints == typing.get_type_hints(type(lines._impl.props))
    updates.cache_property_hints()  # again: no change
    assert base.__dict__["_prop_hints"] is viser_private.CACHED_HINTS
