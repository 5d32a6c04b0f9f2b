"""What long work tells whoever watches it, passed by a context variable: no signature grows, a
call nobody watches pays one lookup, and threads (each with its own context) never see each
other's counts. The work writes the object on its thread; a command reads it from another (a
ticker). :mod:`unstack.reasoner.progress` (sampling) and :mod:`unstack.sim.progress` (unloading)
are two.

Examples
--------
>>> from dataclasses import dataclass
>>> @dataclass
... class Count:
...     done: int = 0
>>> counting = Watched("count", Count)
>>> counting.current() is None
True
>>> with counting.watching() as count:
...     counting.current().done += 1
>>> count.done
1
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from typing import Generic, TypeVar

__all__ = ["Watched"]

T = TypeVar("T")


class Watched(Generic[T]):
    """A kind of progress that work writes and a command watches (``name`` for the context variable)."""

    def __init__(self, name: str, make: Callable[[], T]) -> None:
        self._variable: ContextVar[T | None] = ContextVar(f"unstack_{name}", default=None)
        self._make = make

    @contextmanager
    def watching(self) -> Iterator[T]:
        """Yield a fresh progress object that work in this block (on this thread) writes."""
        progress = self._make()
        token = self._variable.set(progress)
        try:
            yield progress
        finally:
            self._variable.reset(token)

    def current(self) -> T | None:
        """What work on this thread should write, if anybody watches."""
        return self._variable.get()
