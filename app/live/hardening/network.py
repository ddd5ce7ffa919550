"""Where students find the server: the asked port (free, or a one-line reason why not) and the
machine's addresses on the room's network, printed as text and as a QR code for the board.

Nothing here sends a packet or asks a DNS server: the addresses come from the interfaces
themselves (Linux ``SIOCGIFADDR``) and from the route the kernel would take (a UDP socket
``connect`` to a documentation address, which sends nothing).
"""

from __future__ import annotations

import errno
import fcntl
import ipaddress
import socket
import struct

#: TEST-NET-1 (RFC 5737): never routed on the internet; a UDP ``connect`` to it only asks the
#: kernel which local address its route would leave from.
_PROBE_ADDRESS = ("192.0.2.1", 9)
_SIOCGIFADDR = 0x8915
#: Hosts that mean "every interface of this machine".
ANY_HOST = ("0.0.0.0", "::", "")


class PortError(OSError):
    """The asked port cannot be served; ``str()`` is the one line to print."""


def check_port(host: str, port: int) -> None:
    """Raise :class:`PortError` (one line: which port and why) if ``host:port`` cannot be
    listened on now. Port 0 (any free port) always passes. The test binds like the server's
    asyncio listener does (``SO_REUSEADDR``), so a port left in TIME_WAIT is not "busy"."""
    if port == 0:
        return
    if not 0 < port < 65536:
        raise PortError(f"port {port} is not a TCP port (1-65535, or 0 for any free port)")
    family = socket.AF_INET6 if ":" in host else socket.AF_INET
    with socket.socket(family, socket.SOCK_STREAM) as sock:
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        try:
            sock.bind((host, port))
        except OSError as exc:
            raise PortError(port_problem(host, port, bind_errno(exc))) from None


def bind_errno(exc: OSError) -> int | None:
    """The ``errno`` of a failed bind; a host name that names no address of ours counts as
    ``EADDRNOTAVAIL`` (the resolver's own codes are not errno values)."""
    return errno.EADDRNOTAVAIL if isinstance(exc, socket.gaierror) else exc.errno


def port_problem(host: str, port: int, code: int | None = None) -> str:
    """The one line that says why ``host:port`` cannot be served (``code`` an ``errno``)."""
    if code in (errno.EACCES, errno.EPERM):
        why = "is not allowed (ports below 1024 need root)"
    elif code == errno.EADDRNOTAVAIL:
        why = f"cannot be opened: {host} is not an address of this machine"
    else:
        why = "is busy (another program listens on it)"
    return f"port {port} on {host or '0.0.0.0'} {why}; choose another with --port, or --port 0"


def _interface_addresses() -> list[tuple[str, str]]:
    """(interface, IPv4 address) of every interface that has one (Linux ioctl; [] elsewhere)."""
    found: list[tuple[str, str]] = []
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sock:
        for _, name in socket.if_nameindex():
            request = struct.pack("256s", name.encode()[:15])
            try:
                reply = fcntl.ioctl(sock.fileno(), _SIOCGIFADDR, request)
            except OSError:  # no IPv4 address on this interface
                continue
            found.append((name, socket.inet_ntoa(reply[20:24])))
    return found


def _route_address() -> str | None:
    """The local IPv4 address the default route leaves from, or None when there is none."""
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as sock:
        try:
            sock.connect(_PROBE_ADDRESS)
        except OSError:  # offline: no route at all
            return None
        address: str = sock.getsockname()[0]
        return address


def lan_addresses() -> list[tuple[str, str]]:
    """(interface, address) of this machine's non-loopback IPv4 addresses, the one of the
    default route first, link-local (169.254.x.x) ones last."""
    try:
        found = _interface_addresses()
    except OSError:
        found = []
    routed = _route_address()
    if routed and routed not in (a for _, a in found):
        found.append(("route", routed))
    found = [(n, a) for n, a in found if not ipaddress.ip_address(a).is_loopback]
    return sorted(
        found, key=lambda na: (na[1] != routed, ipaddress.ip_address(na[1]).is_link_local)
    )


def qr_text(text: str) -> str:
    """``text`` as a QR code drawn with Unicode half blocks (two rows of modules a line) and
    its four-module quiet zone: light modules are drawn (█), dark ones left blank, so that on
    a terminal with light text on a dark background it is dark on light, as printed."""
    import segno

    code = segno.make(text, error="m", boost_error=False)
    rows = [[bool(v) for v in row] for row in code.matrix_iter(scale=1, border=4)]
    if len(rows) % 2:
        rows.append([False] * len(rows[0]))
    glyph = {(False, False): "█", (True, False): "▄", (False, True): "▀", (True, True): " "}
    return "\n".join(
        "".join(glyph[top, bottom] for top, bottom in zip(upper, lower, strict=True))
        for upper, lower in zip(rows[0::2], rows[1::2], strict=True)
    )


def board(host: str, port: int, link: str = "") -> str:
    """What to print for the lecturer: the URL to open here, and with ``host`` 0.0.0.0 the
    URL(s) to write on the board with a QR code of the first. With a ``link`` (a query, as
    ``preset=t_handle&t=12``), also the link to that state on the first address, and its QR
    code."""
    lines = [f"Poinsot is running at http://{host}:{port}  (Ctrl-C to stop)"]
    shown = host
    if host in ANY_HOST:
        lines = [f"Poinsot is running at http://localhost:{port}  (Ctrl-C to stop)"]
        addresses = lan_addresses()
        if not addresses:
            lines.append("No network address found: students cannot reach this machine yet.")
            shown = "localhost"
        else:
            lines.append("Students open (write it on the board):")
            lines += [f"    http://{address}:{port}    ({name})" for name, address in addresses]
            lines.append(qr_text(f"http://{addresses[0][1]}:{port}"))
            shown = addresses[0][1]
    if link:
        url = f"http://{shown}:{port}/?{link}"
        lines += [f"The link to this state: {url}", qr_text(url)]
    return "\n".join(lines)
