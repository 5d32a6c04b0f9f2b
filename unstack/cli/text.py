"""Text for the terminal: box ids and messages never become control sequences."""

from __future__ import annotations

import re
from collections.abc import Iterable, Sequence
from typing import TYPE_CHECKING

from unstack.checks import counted

if TYPE_CHECKING:
    from rich.table import Table

__all__ = ["counted", "number_table", "printable", "shortened"]


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


#: The longest word (a path, a value) an error or warning line shows whole.
LONGEST_WORD = 240


def shortened(text: str, longest: int = LONGEST_WORD) -> str:
    """``text`` with every word (a run without spaces) longer than ``longest`` characters cut in
    the middle, its length said: an output path of 4,000 characters is not echoed whole.

    Examples
    --------
    >>> shortened("/tmp/" + "d" * 300 + "/x.json: cannot write there", longest=40)
    '/tmp/ddddddddddddddd…(313 characters)…ddddd/x.json: cannot write there'
    """
    head, tail = longest // 2, longest // 3

    def cut(word: re.Match[str]) -> str:
        text = word.group()
        return f"{text[:head]}…({len(text):,} characters)…{text[-tail:]}"

    return re.sub(rf"\S{{{longest + 1},}}", cut, text)


def number_table(title: str, columns: Sequence[str], rows: Iterable[Sequence[str]] = ()) -> Table:
    """A rich table of figures: its title, its columns (each aligned right) and its rows.

    Examples
    --------
    >>> table = number_table("Table I", ("n", "worlds"), [("3", "29"), ("4", "355")])
    >>> [column.header for column in table.columns], table.row_count
    (['n', 'worlds'], 2)
    """
    from rich.table import Table

    table = Table(title=title)
    for column in columns:
        table.add_column(column, justify="right")
    for row in rows:
        table.add_row(*row)
    return table
