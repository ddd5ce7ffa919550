"""Headless Chromium for the pictures and the video: where it is, how it is launched (WebGL
through SwiftShader, nothing past loopback), and a window onto a scene server that draws only the
renders asked of it.

:func:`find_chromium` looks for the executable (``POINSOT_CHROMIUM``, then the PATH) and raises
:class:`BrowserMissing` with how to install it; :func:`headless_chromium` launches it through
playwright and closes it on exit; :func:`sigterm_exits` turns SIGTERM into a normal exit so that
the ``finally`` blocks that stop Chromium and the server run when a command is killed.
"""

from __future__ import annotations

import contextlib
import os
import shutil
import signal
import time
from collections.abc import Iterator
from types import FrameType
from typing import TYPE_CHECKING

import viser

if TYPE_CHECKING:
    from playwright.sync_api import Browser, ViewportSize

#: Where Chromium is looked for (the same variable as the test suite's), then the PATH.
CHROMIUM_ENV = "POINSOT_CHROMIUM"
DEFAULT_CHROMIUM = "/usr/bin/chromium"
#: Flags for headless Chromium here: root, WebGL through SwiftShader, and nothing past loopback.
#: Every host name but 127.0.0.1 resolves to nothing, so no DNS query leaves the machine, and
#: the background services that would phone home (component and safe-browsing updates, sync,
#: metrics, domain reliability, translation, media router, network prediction) are off.
#: What remains is Chromium's IPv6 route probe, a UDP connect() that sends no datagram (no flag
#: turns it off); the loopback test checks that it stays silent. The address bar's popup, which
#: headless Chromium (156) still preloads as a web page of its own for every new page (a renderer
#: and about 0.8 s of CPU each), is off too.
LOOPBACK_ONLY = "MAP * ~NOTFOUND , EXCLUDE 127.0.0.1"
CHROMIUM_ARGS = (
    "--no-sandbox",
    "--disable-gpu",
    "--use-angle=swiftshader",
    "--enable-unsafe-swiftshader",
    f"--host-resolver-rules={LOOPBACK_ONLY}",
    "--no-proxy-server",
    "--disable-quic",
    "--dns-prefetch-disable",
    "--no-first-run",
    "--no-default-browser-check",
    "--no-pings",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--disable-default-apps",
    "--disable-extensions",
    "--disable-breakpad",
    "--disable-domain-reliability",
    "--disable-client-side-phishing-detection",
    "--safebrowsing-disable-auto-update",
    "--metrics-recording-only",
    "--disable-features=NetworkPrediction,OptimizationHints,MediaRouter,DialMediaRouteProvider,"
    "Translate,AutofillServerCommunication,CertificateTransparencyComponentUpdater,AsyncDns,"
    "WebUIOmniboxPopup,WebUIOmniboxAimPopup",
)
INSTALL_HINT = (
    "Install it with `sudo apt-get install chromium` (Debian/Ubuntu; `make chromium` does the "
    f"same), or set {CHROMIUM_ENV} to a Chromium or Chrome executable."
)
#: Exit code when Chromium (or playwright) is missing.
EXIT_NO_BROWSER = 3

#: The browser's window height in CSS pixels. Labels are sized in screen pixels of the live
#: window, so in a render they take (label size / window height) of the picture, whatever its
#: resolution: 720 gives the proportions of the app on a laptop screen. The device scale factor
#: follows the picture's height (up to 2) so that the labels' textures stay sharp.
WINDOW_HEIGHT = 720
MAX_WINDOW_SCALE = 2.0
#: The offline page draws only the renders asked of it. viser's client draws its live view
#: while the canvas is in the window's viewport, and a render asked for costs up to three more
#: live frames (software WebGL: each as dear as the render); moved out of the viewport (the
#: canvas keeps its size, which sizes the labels), the live view is drawn no more and a render
#: draws once. The pixels are the same.
OFF_VIEWPORT_CSS = "body { transform: translateX(-100000px); }"

#: Seconds to wait for the page.
PAGE_TIMEOUT = 60.0


# -- headless Chromium ----------------------------------------------------------------------
class BrowserMissing(RuntimeError):
    """Chromium or the playwright package is not installed."""


def find_chromium() -> str:
    """The Chromium executable, or BrowserMissing with how to install it."""
    wanted = os.environ.get(CHROMIUM_ENV, DEFAULT_CHROMIUM)
    candidates = [wanted] if os.environ.get(CHROMIUM_ENV) else [wanted, "chromium"]
    for candidate in candidates:
        path = candidate if os.path.isabs(candidate) else shutil.which(candidate)
        if path and os.path.isfile(path) and os.access(path, os.X_OK):
            return path
    raise BrowserMissing(f"Chromium was not found (looked for {wanted}). {INSTALL_HINT}")


@contextlib.contextmanager
def sigterm_exits() -> Iterator[None]:
    """Turn SIGTERM into SystemExit for the duration, so that ``finally`` blocks (which stop
    Chromium and the server) run when the command is killed. Main thread only."""
    previous = signal.getsignal(signal.SIGTERM)

    def handler(signum: int, frame: FrameType | None) -> None:
        raise SystemExit(128 + signum)

    signal.signal(signal.SIGTERM, handler)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)


@contextlib.contextmanager
def headless_chromium(executable: str) -> Iterator[Browser]:
    """A launched playwright Browser; closed (and its processes gone) on exit."""
    try:
        from playwright.sync_api import sync_playwright
    except ImportError as exc:
        raise BrowserMissing(
            "the Python package playwright is missing: make install (or pip install "
            "'poinsot[lecture]') installs it; it drives the system's Chromium, no browser "
            "download needed"
        ) from exc
    with sync_playwright() as pw:
        browser = pw.chromium.launch(
            executable_path=executable, headless=True, args=list(CHROMIUM_ARGS)
        )
        try:
            yield browser
        finally:
            browser.close()


def _wait_for_client(server: viser.ViserServer, timeout: float) -> viser.ClientHandle:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        clients = server.get_clients()
        if clients:
            return next(iter(clients.values()))
        time.sleep(0.05)
    raise TimeoutError("the browser did not connect to the scene server")


def open_window(
    browser: Browser,
    server: viser.ViserServer,
    size: tuple[int, int],
    pixel_ratio: float | None = None,
) -> viser.ClientHandle:
    """Open ``server``'s page in a window of WINDOW_HEIGHT CSS pixels with the picture's
    aspect, drawing only the renders asked of it (:data:`OFF_VIEWPORT_CSS`); its client once
    it has connected.

    Renders are drawn at ``pixel_ratio`` times the picture's pixels (None: the window's scale)
    and scaled to the picture. It is fixed (viser's ``fixedDpr`` page parameter): viser's
    client otherwise lowers it while frames are slow, and a software-WebGL browser's always
    are, so that a clip's later frames came out at 3/4 of its resolution, blurred."""
    width, height = size
    window: ViewportSize = {
        "width": max(16, round(WINDOW_HEIGHT * width / height)),
        "height": WINDOW_HEIGHT,
    }
    scale = min(MAX_WINDOW_SCALE, max(1.0, height / WINDOW_HEIGHT))
    context = browser.new_context(viewport=window, device_scale_factor=scale)
    ratio = scale if pixel_ratio is None else pixel_ratio
    url = f"http://{server.get_host()}:{server.get_port()}/?fixedDpr={ratio:g}"
    page = context.new_page()
    page.goto(url, timeout=PAGE_TIMEOUT * 1000)
    page.add_style_tag(content=OFF_VIEWPORT_CSS)
    return _wait_for_client(server, PAGE_TIMEOUT)
