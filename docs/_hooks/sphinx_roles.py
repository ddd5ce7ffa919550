"""A griffe extension for the API reference: the docstrings' Sphinx roles as inline code.

The code's docstrings cross-reference in Sphinx's way (``:class:`~poinsot.physics.Regime```,
``:meth:`omega```); the reference shows the name as code, the module path dropped where the
role's ``~`` asks for it, and reST's double backticks as Markdown's single ones.
"""

from __future__ import annotations

import re
from typing import Any

import griffe

ROLE = re.compile(r":(?:py:)?[a-z]+:`(~?)([^`]+)`")
LITERAL = re.compile(r"``([^`]+)``")


def _role(match: re.Match[str]) -> str:
    short, target = match.group(1), match.group(2)
    return f"`{target.rsplit('.', 1)[-1] if short else target.lstrip('.')}`"


def markdown(text: str) -> str:
    return ROLE.sub(_role, LITERAL.sub(r"`\1`", text))


class SphinxRoles(griffe.Extension):
    def on_instance(self, *, obj: griffe.Object, **kwargs: Any) -> None:
        if obj.docstring is not None:
            obj.docstring.value = markdown(obj.docstring.value)
