"""Following across hosts through a real Redis (:mod:`poinsot.app.live.broker`).

Each test starts Debian's ``redis-server`` on a free loopback port (installed by ``make
chromium``, as nginx is) and two Poinsot servers in this process, each with its own hub linked
to it: two hosts. Probes stand for the browsers; every wait is on an event they receive or a
count the links keep.
"""

from __future__ import annotations

import subprocess
import sys
from collections.abc import Iterator

import pytest

from poinsot.app.devtools.load import services
from poinsot.app.live import broker
from poinsot.app.live.classroom.follow import FollowHub
from tests.app.test_follow import _follow, _lead, _ready, _says, _set
from tests.app.test_nginx import service_or_skip
from tests.conftest import wait_until

redis = pytest.importorskip("redis")
pytestmark = pytest.mark.slow
D = "D = |L|²/2T"


@pytest.fixture
def redis_server(tmp_path) -> Iterator[services.RedisServer]:
    server = service_or_skip(lambda: services.RedisServer(tmp_path)).start()
    yield server
    server.kill()


@pytest.fixture
def two_hosts(redis_server, make_app):
    """Two servers (hosts), each hub linked to the Redis; their links closed after the test."""
    code, line, ok = broker.shared_code(redis_server.url, None, "abc234")
    assert ok
    assert code == "abc234" and "lecturer code shared" in line
    hosts, links = [], []
    for _ in range(2):
        hub = FollowHub(broker.shared_code(redis_server.url, None, "zzz999")[0])
        link = broker.link_hub(hub, redis_server.url)
        assert link.connected.wait(30), "the link never subscribed"
        hosts.append(make_app(follow=hub))
        links.append(link)
    assert [h.follow.code for h in hosts] == ["abc234", "abc234"]  # the first host's code
    yield hosts, links
    for link in links:
        link.close()


def test_two_hosts_follow_one_lead_and_recover_when_redis_returns(
    two_hosts, redis_server, make_probe
):
    (first, second), (link1, link2) = two_hosts
    lead = _ready(make_probe(first))
    _lead(lead, "abc234")
    followers = [_ready(make_probe(app)) for app in (first, second)]
    for probe in followers:
        _follow(probe)
    # The lead's slider move reaches the follower on the other host.
    _set(lead, D, 2.3)
    for probe in followers:
        assert probe.wait_for(lambda p: p.widget(D)[1].value == pytest.approx(2.3), 30)
    assert link2.received > 0 and link1.published > 0

    # Redis killed: the other host's follower keeps the last state and is told so.
    redis_server.kill()
    assert wait_until(lambda: link2.lost == 1 and not link2.connected.is_set(), 30)
    assert followers[1].wait_for(lambda p: _says(p, "keep the last state"), 30)
    assert followers[0].wait_for(lambda p: _says(p, "Following the lecturer"), 30)

    # Redis back: the links reconnect by themselves, and the next move is followed again.
    redis_server.start()
    assert wait_until(lambda: link1.connected.is_set() and link2.connected.is_set(), 30)
    _set(lead, D, 2.1)
    assert followers[1].wait_for(lambda p: p.widget(D)[1].value == pytest.approx(2.1), 30)
    assert followers[1].wait_for(lambda p: _says(p, "Following the lecturer"), 30)
    # One reconnecting thread each, sleeping between tries: no more threads than it started.
    assert link2.lost == 1 and all(t.is_alive() for t in link2._threads)


def test_a_junk_message_on_the_channel_is_refused_and_counted(two_hosts, redis_server):
    (first, _), (link1, _) = two_hosts
    client = redis.Redis.from_url(redis_server.url)
    delivered = first.follow.delivered
    junk = [
        b"not json",
        b"[1, 2]",
        b'{"origin": "x", "kind": "state", "leader": "t", "query": "", "t": "NaN"}',
        b'{"origin": "x", "kind": "state", "leader": "t", "query": "", "t": 1e999}',
        b'{"origin": "x", "kind": "run", "code": "import os"}',
        b'{"origin": "x", "kind": "state", "leader": "t", "query": "", "t": 1, "paused": 0,'
        b' "speed": 1}',
    ]
    for data in junk:
        client.publish(broker.CHANNEL, data)
    good = broker.encode(("lead", "tok"), "elsewhere", 0.0)
    client.publish(broker.CHANNEL, good)  # after the junk: once it is seen, so was the junk
    assert wait_until(lambda: link1.received >= 1, 30)
    assert link1.refused == len(junk)
    assert first.follow.token == "tok" and first.follow.delivered == delivered


def test_unreachable_redis_at_start_is_one_line_and_following_stays_on_the_host():
    url = f"redis://127.0.0.1:{services.free_port()}/0"
    code, line, ok = broker.shared_code(url, "given7", "fallback")
    assert code == "given7" and not ok
    assert "unreachable" in line and "within this host" in line and "\n" not in line
    assert broker._safe("redis://:secret@host:6379/0") == "redis://***@host:6379/0"


def test_without_redis_nothing_changes(poinsot_app):
    import threading

    hub = poinsot_app.follow
    assert hub._uplinks == []
    assert not any(t.name.startswith("poinsot-redis") for t in threading.enumerate())
    # Serving imports neither the link nor redis-py: nothing needs Redis installed.
    code = (
        "import sys; import poinsot.app.cli, poinsot.app.live.server, poinsot.app.live.workers; "
        "assert 'redis' not in sys.modules and 'poinsot.app.live.broker' not in sys.modules"
    )
    subprocess.run([sys.executable, "-c", code], check=True, timeout=120)


def test_a_state_survives_the_channel():
    from poinsot.app.live.classroom.follow import LeadState

    state = LeadState("tok", "preset=x", 1.5, 10.0, False, 2.0, ((1, 2, 3),) * 3, 50, ("A",), ())
    origin, (kind, got) = broker.decode(broker.encode(("state", state), "o", 10.5), 100.0)
    assert origin == "o" and kind == "state"
    assert got.t == pytest.approx(2.5) and got.at == 100.0  # its time on the receiving host
    assert (got.query, got.speed, got.camera, got.trail, got.hidden) == (
        "preset=x",
        2.0,
        ((1.0, 2.0, 3.0),) * 3,
        50,
        ("A",),
    )
