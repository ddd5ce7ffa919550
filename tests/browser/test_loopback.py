"""The project's Chromium reaches nothing past loopback.

Chromium is launched exactly as the screenshot command and the browser tests launch it
(:data:`poinsot.app.exports.chromium.CHROMIUM_ARGS`), under ``strace``, and loads the live app
from a loopback server. Every socket call that names an internet address is then checked: TCP and
UDP connections and datagrams go to 127.0.0.0/8 only. Chromium's IPv6 route probe (a UDP
``connect()`` that only asks the kernel for a route) is allowed, provided that nothing is ever
written on that socket.
"""

from __future__ import annotations

import concurrent.futures
import re
import shutil
import stat

import pytest
from conftest import chromium_or_fail, in_ci

from poinsot.app.exports.chromium import headless_chromium

pytestmark = pytest.mark.browser

_CALL = re.compile(r"^\d+\s+(?P<call>connect|sendto|sendmsg|sendmmsg|write)\((?P<args>.*)")
_INET = re.compile(r'inet_addr\("(?P<v4>[^"]+)"\)|inet_pton\(AF_INET6, "(?P<v6>[^"]+)"')
#: strace -yy's socket annotation: ``21<UDPv6:[15408]>`` or ``9<TCP:[127.0.0.1:1->127.0.0.1:2]>``.
_SOCKET = re.compile(r"^\d+<(?P<proto>TCP|UDP)v?6?:\[(?P<info>[^\]]*)\]")
_PEER = re.compile(r"->\[?(?P<peer>[0-9a-fA-F.:]+?)\]?:\d+$")


def _strace_or_skip() -> str:
    path = shutil.which("strace")
    if path:
        return path
    message = "strace not found: run `make chromium` (installs Debian's chromium and strace)"
    if in_ci():
        pytest.fail(message + " [CI=true: this test must run]")
    pytest.skip(message)


def _is_loopback(address: str) -> bool:
    return address.startswith("127.") or address in ("::1", "::ffff:127.0.0.1")


def outside_loopback(trace: str) -> tuple[list[str], int]:
    """(calls that reach past loopback, silent route probes) in an ``strace -f -yy`` log."""
    leaks: list[str] = []
    probes: set[str] = set()  # socket inodes of UDP sockets connected past loopback
    for line in trace.splitlines():
        m = _CALL.match(line)
        if m is None:
            continue
        call, args = m["call"], m["args"]
        sock = _SOCKET.match(args)
        inet = _INET.search(args)
        address = (inet["v4"] or inet["v6"]) if inet else None
        if call == "connect" and address is not None and not _is_loopback(address):
            if sock is not None and sock["proto"] == "UDP":
                probes.add(sock["info"])  # a route probe: no packet yet
            else:
                leaks.append(line)
            continue
        if call == "connect" or sock is None:
            continue  # loopback, unix and netlink sockets, pipes and files
        if sock["info"] in probes:
            leaks.append(f"data on a route-probe socket: {line}")
        elif address is not None and not _is_loopback(address):
            leaks.append(line)
        else:
            peer = _PEER.search(sock["info"])
            if peer is not None and not _is_loopback(peer["peer"]):
                leaks.append(line)
    return leaks, len(probes)


def _visit(chromium: str, port: int) -> bool:
    """Load the app, then ask for a public name; True if that fetch failed (as it must)."""
    with headless_chromium(chromium) as browser:
        page = browser.new_page()
        page.goto(f"http://127.0.0.1:{port}/", timeout=60_000)
        page.wait_for_selector("canvas", timeout=60_000)
        failed = page.evaluate("() => fetch('http://example.com/').then(() => false, () => true)")
        page.wait_for_timeout(2000)
        return bool(failed)


def test_the_browser_resolves_and_reaches_nothing_but_loopback(tmp_path, make_app):
    chromium = chromium_or_fail()
    strace = _strace_or_skip()
    log = tmp_path / "trace.log"
    wrapper = tmp_path / "chromium"
    wrapper.write_text(
        "#!/bin/sh\n"
        f'exec "{strace}" -f -qq -yy -o "{log}" '
        "-e trace=connect,sendto,sendmsg,sendmmsg,write "
        f'"{chromium}" "$@"\n'
    )
    wrapper.chmod(wrapper.stat().st_mode | stat.S_IXUSR)
    app = make_app()
    # A thread of its own: playwright's sync API refuses to start inside the event loop that
    # the session's shared browser (conftest) keeps running on this thread.
    with concurrent.futures.ThreadPoolExecutor(1) as pool:
        failed = pool.submit(_visit, str(wrapper), app.port).result(timeout=180)
    assert failed, "a public host name resolved"
    trace = log.read_text(errors="replace")
    assert "connect(" in trace, "strace saw no socket calls at all"
    assert re.search(r"connect\(\d+<TCP", trace), "no TCP connection traced (to the app)"
    leaks, probes = outside_loopback(trace)
    assert leaks == [], "\n".join(leaks[:20])
    assert probes <= 10, probes


def test_the_trace_reader_catches_a_dns_query_and_a_talking_probe():
    """The reader above is itself checked on hand-written trace lines."""
    trace = "\n".join(
        [
            "10  connect(21<UDP:[901]>, {sa_family=AF_INET, sin_port=htons(53), "
            'sin_addr=inet_addr("10.255.255.53")}, 16) = 0',
            '10  write(21<UDP:[901]>, "query", 5) = 5',
            "10  connect(22<UDPv6:[902]>, {sa_family=AF_INET6, sin6_port=htons(443), "
            'inet_pton(AF_INET6, "2001:4860:4860::8888", &sin6_addr), sin6_scope_id=0}, 28) = 0',
            "11  connect(23<TCP:[903]>, {sa_family=AF_INET, sin_port=htons(8080), "
            'sin_addr=inet_addr("127.0.0.1")}, 16) = 0',
            '11  write(23<TCP:[127.0.0.1:5000->127.0.0.1:8080]>, "GET", 3) = 3',
            "11  connect(24<TCP:[904]>, {sa_family=AF_INET, sin_port=htons(443), "
            'sin_addr=inet_addr("93.184.216.34")}, 16) = -1',
            '11  write(25<TCP:[10.0.0.2:5000->93.184.216.34:443]>, "x", 1) = 1',
        ]
    )
    leaks, probes = outside_loopback(trace)
    assert probes == 2  # the DNS socket and the IPv6 route probe were connected
    assert len(leaks) == 3, leaks
    assert "route-probe" in leaks[0] and "93.184.216.34" in leaks[1] and "93.184" in leaks[2]
