"""Text for the terminal: box ids and messages never become control sequences."""

from __future__ import annotations

__all__ = ["printable"]


def printable(text: str) -> str:
    """``text`` with control characters escaped (``\\x1b`` for ESC), safe for a terminal.

    Examples
    --------
    >>> printable("box\\x1b[31m")
    'box\\\\x1b[31m'
    """
    if text.isprintable():
        return text
    return "".join(c if c.isprintable() else c.encode("unicode_escape").decode("ascii") for c in text)
