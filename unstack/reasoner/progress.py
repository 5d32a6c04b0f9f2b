"""How far a long sampling run is, for whoever prints progress: the sweeps recorded of those
asked in the group being sampled.

Passed by a context variable rather than by argument (:mod:`unstack.watching`), so that no
signature grows, a call that does not watch pays one lookup a group, and threads (each with its
own context) never see each other's counts. A command watches its decision with
``watching_sampling()`` and reads the object it yields from another thread (a ticker); the
sampler writes it on the calling thread.

Examples
--------
>>> import numpy as np
>>> from unstack.reasoner.sampling import sampled_marginals
>>> half = np.full((3, 3), 0.5); np.fill_diagonal(half, 0)
>>> with watching_sampling() as watch:
...     _ = sampled_marginals(half, samples=4096, seed=0)
>>> watch.done, watch.total, watch.line() is None  # the group's sampling is over
(4096, 4096, True)
"""

from __future__ import annotations

import time
from dataclasses import dataclass

from unstack.watching import Watched

__all__ = ["SamplingProgress", "sampling_progress", "watching_sampling"]


@dataclass
class SamplingProgress:
    """The group being sampled: its boxes, the sweeps recorded over all chains, the sweeps asked
    (``None`` under a time limit) and when its sampling started (``time.perf_counter``)."""

    boxes: int = 0
    done: int = 0
    total: int | None = None
    started: float = 0.0

    def start(self, boxes: int, total: int | None) -> None:
        """A new group's sampling begins."""
        self.boxes, self.done, self.total, self.started = boxes, 0, total, time.perf_counter()

    def finish(self) -> None:
        """The group's sampling is over: nothing to say until the next group starts."""
        self.boxes = 0

    def line(self) -> str | None:
        """Where the run is, in words (``None`` while no group is being sampled).

        Examples
        --------
        >>> progress = SamplingProgress()
        >>> progress.start(40, 3_000_000)
        >>> progress.line()
        'sampling a group of 40 boxes: 0 of 3,000,000 sweeps'
        """
        if self.boxes == 0:
            return None
        if self.total is None:
            return f"sampling a group of {self.boxes} boxes until the time limit: {self.done:,} sweeps"
        return f"sampling a group of {self.boxes} boxes: {self.done:,} of {self.total:,} sweeps"

    def seconds_left(self) -> float | None:
        """The group's remaining seconds at its rate so far (``None`` before a sweep is recorded,
        or under a time limit)."""
        seconds = time.perf_counter() - self.started
        if self.total is None or self.done == 0 or seconds <= 0:
            return None
        return seconds * (self.total - self.done) / self.done


_SAMPLING = Watched("sampling_progress", SamplingProgress)
#: Yield the :class:`SamplingProgress` that sampling in this block (on this thread) writes.
watching_sampling = _SAMPLING.watching
#: What sampling on this thread should write, if anybody watches.
sampling_progress = _SAMPLING.current
