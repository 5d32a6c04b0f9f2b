"""A pybullet world of its own: the container, the boxes, stepping and settling.

Each :class:`PhysicsWorld` opens its own DIRECT client (never pybullet's global one), so
simulations in one process do not share state and a world's result depends only on the
calls made on it. Sleeping is disabled on every box: with sleeping on, a box whose
support is taken away may stay asleep in the air.

Examples
--------
>>> from unstack.sim.settings import SimulationSettings
>>> with PhysicsWorld(SimulationSettings(boxes=(1, 1))) as world:
...     box = world.add_box([0.4, 0.3, 0.3], [1.0, 0.0, 0.5], [0, 0, 0, 1], mass=5.0)
...     seconds = world.settle()
...     round(float(world.poses()[0][0, 2]), 2)   # resting on the floor: z = half its height
0.15
"""

from __future__ import annotations

import contextlib
import os
import sys
import threading
from collections.abc import Iterator
from types import ModuleType
from typing import Any

import numpy as np

from unstack.geometry import rotation_angles_deg
from unstack.sim.settings import SimulationSettings

__all__ = ["PhysicsWorld", "import_pybullet"]

#: Wall thickness of the container's static parts (metres).
WALL = 0.1
#: Length of the apron in front of the door that catches boxes falling out (metres).
APRON = 1.5


_IMPORT_LOCK = threading.Lock()


@contextlib.contextmanager
def _quiet_c_output() -> Iterator[None]:
    """Silence C-level stdout and stderr while pybullet is first imported.

    pybullet's module initialisation prints its build time with C ``printf``, which would
    corrupt JSON on stdout. This is the one place unstack touches process-wide state, and
    it is confined: it runs once per process (under a lock), only when pybullet is not
    imported yet, for the duration of the import. A host that minds can import pybullet
    itself first. Connecting needs no silencing (see :func:`_direct_client`).
    """
    import ctypes

    libc = ctypes.CDLL(None)
    sys.stdout.flush()
    sys.stderr.flush()
    libc.fflush(None)
    saved = [os.dup(1), os.dup(2)]
    with open(os.devnull, "wb") as devnull:
        os.dup2(devnull.fileno(), 1)
        os.dup2(devnull.fileno(), 2)
    try:
        yield
    finally:
        libc.fflush(None)
        for fd, copy in zip((1, 2), saved, strict=True):
            os.dup2(copy, fd)
            os.close(copy)


def import_pybullet() -> tuple[ModuleType, Any]:
    """Import pybullet and its ``BulletClient``; a clear error if it is missing.

    The first import in a process is silenced (see :func:`_quiet_c_output`); later calls
    change nothing.
    """
    try:
        with _IMPORT_LOCK:
            if "pybullet" in sys.modules:
                import pybullet
            else:
                with _quiet_c_output():
                    import pybullet
            from pybullet_utils.bullet_client import BulletClient
    except ImportError as error:  # pragma: no cover - depends on the installation
        from unstack.errors import UnstackError

        raise UnstackError(
            "the simulator needs pybullet: pip install 'unstack[sim]' (or pip install pybullet)"
        ) from error
    return pybullet, BulletClient


def _direct_client(pybullet: ModuleType, bullet_client: Any) -> Any:
    """A ``BulletClient`` on a new DIRECT server, connected without an options string.

    ``BulletClient(connection_mode=DIRECT)`` passes ``options=""``, and pybullet echoes any
    options string (``argv[0]=``) on C stdout; ``pybullet.connect(DIRECT)`` alone prints
    nothing, so no output needs silencing.
    """
    client = bullet_client.__new__(bullet_client)
    client._shapes = {}
    client._pid = os.getpid()
    client._client = -1  # not connected yet: a Ctrl-C inside connect leaves nothing for __del__ to close
    client._client = pybullet.connect(pybullet.DIRECT)
    return client


class PhysicsWorld:
    """The container with its static walls, a removable door and the boxes in it.

    Parameters
    ----------
    settings : SimulationSettings
        Container extents, friction and time step are read from it.
    door : bool
        Start with the temporary door wall at x = 0.
    """

    def __init__(self, settings: SimulationSettings, *, door: bool = True) -> None:
        pybullet, bullet_client = import_pybullet()
        self.settings = settings
        self.pybullet = pybullet
        self.client = _direct_client(pybullet, bullet_client)
        self.client.setGravity(0.0, 0.0, -9.81)
        self.client.setTimeStep(settings.pile.time_step)
        self.client.setPhysicsEngineParameter(deterministicOverlappingPairs=1)
        self.boxes: list[int] = []
        self.static: list[int] = []
        self.door: int | None = None
        self._build_container()
        if door:
            self.close_door()

    # -- construction -------------------------------------------------------------------
    def _static_box(self, half_extents: list[float], center: list[float]) -> int:
        client = self.client
        shape = client.createCollisionShape(client.GEOM_BOX, halfExtents=half_extents)
        body = int(client.createMultiBody(baseMass=0.0, baseCollisionShapeIndex=shape, basePosition=center))
        client.changeDynamics(body, -1, lateralFriction=self.settings.pile.friction)
        return body

    def _build_container(self) -> None:
        box = self.settings.container
        depth, width, height = box.depth, box.width, box.height
        half = WALL / 2.0
        parts = [
            # floor (reaching out over the apron in front of the door)
            ([(depth + APRON) / 2.0 + WALL, width / 2.0 + WALL, half], [(depth - APRON) / 2.0, 0.0, -half]),
            # ceiling
            ([depth / 2.0 + WALL, width / 2.0 + WALL, half], [depth / 2.0, 0.0, height + half]),
            # back wall
            ([half, width / 2.0 + WALL, height / 2.0], [depth + half, 0.0, height / 2.0]),
            # side walls
            ([depth / 2.0, half, height / 2.0], [depth / 2.0, width / 2.0 + half, height / 2.0]),
            ([depth / 2.0, half, height / 2.0], [depth / 2.0, -width / 2.0 - half, height / 2.0]),
        ]
        self.static = [self._static_box(extents, center) for extents, center in parts]

    def close_door(self) -> None:
        """Put the temporary door wall at x = 0 (boxes are dropped behind it)."""
        if self.door is None:
            box = self.settings.container
            self.door = self._static_box(
                [WALL / 2.0, box.width / 2.0, box.height / 2.0], [-WALL / 2.0, 0.0, box.height / 2.0]
            )

    def open_door(self) -> None:
        """Take the door wall away (before the pile is saved or scanned)."""
        if self.door is not None:
            self.client.removeBody(self.door)
            self.door = None

    def add_box(self, size: Any, position: Any, orientation_xyzw: Any, *, mass: float) -> int:
        """Add a dynamic box; returns its body id."""
        client = self.client
        half = [float(value) / 2.0 for value in size]
        shape = client.createCollisionShape(client.GEOM_BOX, halfExtents=half)
        visual = client.createVisualShape(client.GEOM_BOX, halfExtents=half)
        body = int(
            client.createMultiBody(
                baseMass=float(mass),
                baseCollisionShapeIndex=shape,
                baseVisualShapeIndex=visual,
                basePosition=[float(value) for value in position],
                baseOrientation=[float(value) for value in orientation_xyzw],
            )
        )
        client.changeDynamics(
            body,
            -1,
            lateralFriction=self.settings.pile.friction,
            activationState=client.ACTIVATION_STATE_DISABLE_SLEEPING,
        )
        self.boxes.append(body)
        return body

    def add_fixed_blocks(self, sizes: Any, centers: Any) -> list[int]:
        """Add static, axis-aligned blocks (unseen material that holds up what rests on it);
        their body ids in the order given.

        Blocks of one size share a collision shape and are created in one batched call, about
        eight times faster than a call each (the unseen space of a belief world is a few
        hundred blocks of a few dozen sizes).

        Examples
        --------
        >>> from unstack.sim.settings import SimulationSettings
        >>> with PhysicsWorld(SimulationSettings(boxes=(1, 1))) as world:
        ...     blocks = world.add_fixed_blocks([[0.2, 0.2, 0.2]] * 3, [[1.0, y, 0.1] for y in (-0.5, 0.0, 0.5)])
        ...     len(blocks), len(world.static)
        (3, 8)
        """
        halves = [tuple(float(value) / 2.0 for value in size) for size in sizes]
        places = [[float(value) for value in center] for center in centers]
        if len(halves) != len(places):
            raise ValueError(f"{len(halves)} block sizes for {len(places)} centres")
        by_size: dict[tuple[float, ...], list[int]] = {}
        for row, half in enumerate(halves):
            by_size.setdefault(half, []).append(row)
        client = self.client
        bodies = [0] * len(places)
        for half, rows in by_size.items():
            shape = client.createCollisionShape(client.GEOM_BOX, halfExtents=list(half))
            if len(rows) == 1:  # pybullet returns one id, not a tuple, for a batch of one
                created = [
                    client.createMultiBody(baseMass=0.0, baseCollisionShapeIndex=shape, basePosition=places[rows[0]])
                ]
            else:
                created = client.createMultiBody(
                    baseMass=0.0, baseCollisionShapeIndex=shape, batchPositions=[places[row] for row in rows]
                )
            for row, body in zip(rows, created, strict=True):
                client.changeDynamics(body, -1, lateralFriction=self.settings.pile.friction)
                bodies[row] = int(body)
        self.static.extend(bodies)
        return bodies

    def remove_box(self, body: int) -> None:
        """Delete a box for good (only while building a pile, never after ``saveState``)."""
        self.client.removeBody(body)
        self.boxes.remove(body)

    # -- state --------------------------------------------------------------------------
    def poses(self, bodies: list[int] | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Positions (k, 3) and orientations ``xyzw`` (k, 4) of the boxes."""
        bodies = self.boxes if bodies is None else bodies
        positions = np.empty((len(bodies), 3))
        orientations = np.empty((len(bodies), 4))
        for row, body in enumerate(bodies):
            position, orientation = self.client.getBasePositionAndOrientation(body)
            positions[row] = position
            orientations[row] = orientation
        return positions, orientations

    def speeds(self, bodies: list[int] | None = None) -> np.ndarray:
        """Linear speed of the boxes (all by default), m/s."""
        bodies = self.boxes if bodies is None else bodies
        return np.array([np.linalg.norm(self.client.getBaseVelocity(body)[0]) for body in bodies])

    def step(self, seconds: float) -> None:
        """Advance the simulation by (about) ``seconds``."""
        for _ in range(max(1, round(seconds / self.settings.pile.time_step))):
            self.client.stepSimulation()

    def settle(self, max_time: float | None = None) -> float:
        """Step until the pile is still; returns the simulated seconds (capped).

        Still means: over ``settle_windows`` consecutive windows of ``settle_window``
        seconds, no box moved more than ``settle_displacement`` nor turned more than
        ``settle_rotation_deg``. Velocity criteria either creep or never end.
        """
        pile = self.settings.pile
        cap = pile.settle_max_time if max_time is None else max_time
        elapsed = 0.0
        still = 0
        positions, orientations = self.poses()
        while elapsed < cap:
            self.step(pile.settle_window)
            elapsed += pile.settle_window
            new_positions, new_orientations = self.poses()
            if len(self.boxes) == 0:
                return elapsed
            moved = float(np.max(np.linalg.norm(new_positions - positions, axis=1)))
            turned = float(np.max(rotation_angles_deg(orientations, new_orientations)))
            positions, orientations = new_positions, new_orientations
            still = still + 1 if moved < pile.settle_displacement and turned < pile.settle_rotation_deg else 0
            if still >= pile.settle_windows:
                break
        return elapsed

    def close(self) -> None:
        """Disconnect the client."""
        with contextlib.suppress(Exception):
            self.client.disconnect()

    def __enter__(self) -> PhysicsWorld:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.close()
