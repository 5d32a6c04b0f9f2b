"""Work kept from one decision to the next (the steps of an unloading plan).

Taking one box out of a scene changes only the group of linked boxes it belonged to: every
other group has the same probabilities, so its marginals (exact or sampled) are reused as
they are. The group that lost the box is sampled again, but its chains start from where the
previous step's chains ended, restricted to the remaining boxes (a preorder restricted to
fewer boxes is still a preorder), so a short burn-in suffices. With a seed and a sample
budget the whole plan stays reproducible: what is reused depends only on the previous steps.

Examples
--------
>>> from unstack.supports import Supports
>>> from unstack.reasoner.decision import decide
>>> supports = Supports(["a", "b", "c"], [[0, 0.9, 0], [0.1, 0, 0], [0, 0, 0]])
>>> work = WorkCache()
>>> first = decide(supports, cache=work)
>>> second = decide(supports.subset(["a", "b"]), cache=work)
>>> work.reused
1
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

__all__ = ["WARM_BURN_IN", "WorkCache"]

#: Sweeps per chain discarded after a warm start (a cold start discards 64).
WARM_BURN_IN = 16


@dataclass
class WorkCache:
    """Group results and final chain states, by the ids of the group's boxes.

    Attributes
    ----------
    results : dict
        ``(ids, method, probabilities, budget) -> result`` of every group decided so far.
    chains : dict
        ``ids -> (chains, len(ids))`` final chain states of the sampled groups.
    reused : int
        Group results taken from the cache.
    warm_starts : int
        Sampled groups started from a previous chain state.
    """

    results: dict[tuple[Any, ...], Any] = field(default_factory=dict)
    chains: dict[tuple[str, ...], np.ndarray] = field(default_factory=dict)
    reused: int = 0
    warm_starts: int = 0

    def warm_start(self, ids: tuple[str, ...]) -> np.ndarray | None:
        """Chain states for the boxes ``ids`` from the smallest stored group holding them all."""
        from unstack.reasoner.sampling import restrict_worlds

        wanted = set(ids)
        best: tuple[str, ...] | None = None
        for stored in self.chains:
            if wanted <= set(stored) and (best is None or len(stored) < len(best)):
                best = stored
        if best is None:
            return None
        position = {box: k for k, box in enumerate(best)}
        self.warm_starts += 1
        return restrict_worlds(self.chains[best], np.array([position[box] for box in ids], dtype=np.int64))
