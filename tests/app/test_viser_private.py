"""Each private viser name that :mod:`poinsot.app.viser_private` relies on, pinned.

When viser moves one of them, the test of that name fails and says which viser it found and
which one the adapter was written for (:class:`~poinsot.app.viser_private.ViserChanged`).
"""

from __future__ import annotations

import dataclasses
import inspect
import threading

import pytest
import viser
import websockets.asyncio.server
from conftest import session_of, wait_until
from viser import _messages

from poinsot.app import viser_private
from poinsot.app.live.guard import WireGuard
from poinsot.app.live.transfers import handle_id

WRITTEN_FOR = f"written for viser {viser_private.VISER_SERIES}.x, found viser {viser.__version__}"


def test_the_installed_viser_is_the_series_the_adapter_was_written_for():
    assert viser.__version__.startswith(viser_private.VISER_SERIES + "."), WRITTEN_FOR
    viser_private.check()


@pytest.mark.parametrize("name", sorted(viser_private.ALLOWED))
def test_each_allowed_message_mirrors_viser_s_own_fields(name):
    theirs = getattr(_messages, name, None)
    assert theirs is not None and dataclasses.is_dataclass(theirs), f"{name}: {WRITTEN_FOR}"
    fields = [f.name for f in dataclasses.fields(theirs) if f.init]
    assert list(viser_private.ALLOWED[name].__struct_fields__) == fields, WRITTEN_FOR


def test_a_moved_name_is_reported_with_the_version(monkeypatch):
    monkeypatch.setattr(_messages, "CommandTriggerMessage", None)
    with pytest.raises(viser_private.ViserChanged, match=rf"viser {viser.__version__} .* 1\.1"):
        viser_private.check()


def test_viser_builds_its_server_through_websockets_serve():
    """The handshake hook rides on the one ``serve`` call of viser's server thread."""
    source = inspect.getsource(viser.infra._infra.WebsockServer._background_worker)
    assert "websockets.asyncio.server.serve(" in source, WRITTEN_FOR
    assert "process_request=" in source, WRITTEN_FOR
    with pytest.raises(viser_private.ViserChanged, match="websockets.asyncio.server.serve"):
        with viser_private.hooked_server(lambda c, r: None, _never):
            pass  # nothing built: the hook is never called
    assert websockets.asyncio.server.serve.__module__ == "websockets.asyncio.server"


def _never(exc: BaseException):
    raise AssertionError(exc)


def test_the_connection_names_hold_on_a_live_server(poinsot_app, probe):
    server = poinsot_app.server
    infra = viser_private.infra(server)
    assert isinstance(infra, viser.infra.WebsockServer), WRITTEN_FOR
    session = session_of(poinsot_app)
    client_id = session.client.client_id
    connection = viser_private.live_connection(server, client_id)
    assert isinstance(connection, websockets.asyncio.server.ServerConnection), WRITTEN_FOR
    assert "recv" in vars(connection), "the guard's recv wrapper is not on the connection"
    assert set(infra._client_state_from_id) == {client_id}, WRITTEN_FOR
    assert client_id in server._connected_clients, WRITTEN_FOR
    assert not viser_private.render_requested(server, client_id)
    assert isinstance(poinsot_app.guard, WireGuard)


def test_the_gui_names_hold_on_a_live_server(poinsot_app, probe):
    session = session_of(poinsot_app)
    handle = session.panel.widgets.speed
    uuid = handle_id(handle)
    found = viser_private.gui_input_handle(poinsot_app.server, session.client.client_id, uuid)
    assert found is handle, WRITTEN_FOR
    assert viser_private.gui_input_handle(poinsot_app.server, 10**6, "nope") is None


def test_a_render_request_is_seen_while_it_waits(poinsot_app, probe):
    """``get_render`` registers a handler on the client's connection until its answer."""
    session = session_of(poinsot_app)
    client = session.client
    answered = []
    # the probe never answers: it times out
    thread = threading.Thread(target=lambda: answered.append(_render_or_timeout(client)))
    thread.start()
    waiting = lambda: viser_private.render_requested(poinsot_app.server, client.client_id)  # noqa: E731
    assert wait_until(waiting, 10), WRITTEN_FOR
    thread.join(10)
    assert answered == ["timed out"]
    assert not waiting()


def _render_or_timeout(client) -> str:
    try:
        client.get_render(8, 8, timeout=1.0)
    except TimeoutError:
        return "timed out"
    return "rendered"


def test_the_share_handlers_are_where_viser_put_them(make_app):
    app = make_app()
    assert not viser_private.share_enabled(app.server)
    plain = viser.ViserServer(host="127.0.0.1", port=0, verbose=False)
    try:
        assert viser_private.share_enabled(plain), WRITTEN_FOR
        viser_private.disable_share(plain)
        assert not viser_private.share_enabled(plain)
    finally:
        plain.stop()
