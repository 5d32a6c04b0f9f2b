"""A pile in its physics world: the boxes' bodies, what they are, and the boxes that fell out.

Shared by the ways a pile is made (:mod:`unstack.sim.piles`, :mod:`unstack.sim.structures`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from unstack.sim.world import PhysicsWorld

__all__ = ["Pile", "PileBox", "delete_fallen"]


@dataclass
class PileBox:
    """A box of the pile: its body in the world and what it is."""

    body: int
    size: np.ndarray
    mass: float


@dataclass
class Pile:
    """A settled pile, with the door open, still alive in its physics world."""

    world: PhysicsWorld
    boxes: list[PileBox] = field(default_factory=list)
    refills: int = 0

    def close(self) -> None:
        """Close the physics world."""
        self.world.close()

    def __enter__(self) -> Pile:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.close()


def delete_fallen(world: PhysicsWorld, pile: Pile) -> int:
    """Delete the boxes whose centroid left the container; returns how many."""
    container = world.settings.container
    positions, _ = world.poses([box.body for box in pile.boxes])
    inside = (
        (positions[:, 0] > 0.0)
        & (positions[:, 0] < container.depth)
        & (np.abs(positions[:, 1]) < container.width / 2.0)
        & (positions[:, 2] > 0.0)
        & (positions[:, 2] < container.height)
    )
    for box, keep in zip(list(pile.boxes), inside, strict=True):
        if not keep:
            world.remove_box(box.body)
            pile.boxes.remove(box)
    return int(np.count_nonzero(~inside))
