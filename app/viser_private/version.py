"""The viser release series the adapter was written for, and the error raised when viser moved."""

from __future__ import annotations

import viser

#: The viser release series this module was written for.
VISER_SERIES = "1.1"


class ViserChanged(RuntimeError):
    """A private name or shape this module relies on is not what viser 1.1.x had."""

    def __init__(self, what: str) -> None:
        super().__init__(
            f"viser {viser.__version__} is not the viser {VISER_SERIES}.x that "
            f"poinsot.app.viser_private was written for: {what}"
        )
