"""Where a long unloading run is, for whoever prints progress: the pile, the decision maker, the
picks made and the boxes still in place.

Passed by a context variable (:mod:`unstack.watching`), as the sampler's progress is: a command
watches with ``watching_picks()`` and reads the object it yields from another thread (a
ticker); the unloading writes it on the calling thread. Piles run in other processes (``--jobs``, a dask
cluster) are not seen.

Examples
--------
>>> with watching_picks() as watch:
...     watch.pile("config-0003", "lookahead")
...     watch.pick(12, 21)
...     watch.line()
'config-0003, lookahead: 12 picks, 21 boxes left'
"""

from __future__ import annotations

from dataclasses import dataclass

from unstack.watching import Watched

__all__ = ["PickProgress", "pick_progress", "watching_picks"]


@dataclass
class PickProgress:
    """The pile being emptied, by which decision maker, the picks made so far and the boxes left."""

    name: str = ""
    maker: str = ""
    picks: int = 0
    left: int = 0

    def pile(self, name: str, maker: str) -> None:
        """A decision maker starts emptying a pile."""
        self.name, self.maker, self.picks, self.left = name, maker, 0, 0

    def pick(self, picks: int, left: int) -> None:
        """``picks`` boxes are out; ``left`` are still in place."""
        self.picks, self.left = picks, left

    def line(self) -> str | None:
        """Where the run is, in words (``None`` before a pile starts)."""
        if not self.name:
            return None
        return f"{self.name}, {self.maker}: {self.picks} picks, {self.left} boxes left"


_PICKS = Watched("pick_progress", PickProgress)
#: Yield the :class:`PickProgress` that unloading in this block (on this thread) writes.
watching_picks = _PICKS.watching
#: What unloading on this thread should write, if anybody watches.
pick_progress = _PICKS.current
