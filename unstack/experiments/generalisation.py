"""The generalisation suite: canonical scenes, two kinds of cloud, the default decision checked.

Every canonical scene (:mod:`unstack.experiments.canonical_scenes`) is scanned twice: by the
project's range sensor (pybullet's renderer from the door, :mod:`unstack.sim.sensor`) and by
:func:`unstack.clouds.surface_cloud` (faces sampled at another density, from a moved
viewpoint, with depth noise and missing faces). A decision is *right* when its choice is a
pickable box (it holds up nothing) and its expected costs respect the scene's bounds: a box
that holds up k boxes costs at least ``HOLD_SHARE * k``, a pickable box less than
:data:`FREE_MAX`.

Examples
--------
>>> from unstack.experiments.canonical_scenes import build_case
>>> scene = canonical_scene(build_case("plain_stack", seed=1), cloud="surface", seed=1)
>>> len(scene.detected) >= 3, scene.points.shape[1]
(True, 3)
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from unstack.experiments.canonical_scenes import CANONICAL_KINDS, CanonicalCase, build_case
from unstack.scene import Scene

__all__ = ["CLOUDS", "FREE_MAX", "HOLD_SHARE", "SuiteResult", "canonical_scene", "check_decision", "run_suite"]

#: The two ways a canonical scene is scanned.
CLOUDS = ("sensor", "surface")
#: A box that holds up k boxes must cost at least this share of k.
HOLD_SHARE = 0.5
#: A pickable box must cost less than this.
FREE_MAX = 0.5


def _sensor_cloud(case: CanonicalCase, seed: int) -> np.ndarray:
    from unstack.sim.sensor import scan_pile
    from unstack.sim.settings import SensorSettings, SimulationSettings
    from unstack.sim.world import PhysicsWorld

    sensor = SensorSettings()
    with PhysicsWorld(SimulationSettings(boxes=(1, 1)), door=False) as world:
        for box in case.boxes:
            world.add_box(box.size, box.position, box.orientation_xyzw, mass=5.0)
        scan = scan_pile(world, sensor, seed=seed)
    points = scan.points
    if not case.in_container:  # in the open: the boxes and the floor only
        keep = (scan.point_boxes >= 0) | (np.abs(points[:, 2]) < 0.005)
        points = points[keep]
    return points


def _surface(case: CanonicalCase, seed: int) -> np.ndarray:
    from unstack.clouds import surface_cloud

    rng = np.random.default_rng(seed)
    viewpoint = np.array([-1.8, 0.0, 1.6]) + rng.uniform(-0.4, 0.4, size=3)
    return surface_cloud(
        case.boxes,
        viewpoint=viewpoint,
        spacing=float(rng.uniform(0.012, 0.03)),
        depth_noise=float(rng.uniform(0.0, 0.006)),
        missing_faces=0.15,
        seed=int(rng.integers(2**32)),
    )


def canonical_scene(case: CanonicalCase, *, cloud: str, seed: int) -> Scene:
    """The case as a scene with a cloud from the range sensor (``"sensor"``) or ``"surface"``."""
    from unstack.errors import UnstackError

    if cloud not in CLOUDS:
        raise UnstackError(f"unknown cloud {cloud!r}; expected one of {', '.join(CLOUDS)}")
    points = _sensor_cloud(case, seed) if cloud == "sensor" else _surface(case, seed)
    return Scene(case.boxes, points, case.detected, metadata={"canonical": case.kind, "cloud": cloud},
                 source=f"<{case.kind} seed {seed}, {cloud} cloud>")  # fmt: skip


@dataclass(frozen=True)
class SuiteResult:
    """One decision of the suite and whether it is right."""

    kind: str
    seed: int
    cloud: str
    in_container: bool
    choice: str
    pickable: tuple[str, ...]
    expected_costs: dict[str, float]
    problems: tuple[str, ...]
    warnings: tuple[str, ...]

    @property
    def right(self) -> bool:
        """The choice is pickable and every bound holds."""
        return not self.problems

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready."""
        return {
            "kind": self.kind,
            "seed": self.seed,
            "cloud": self.cloud,
            "in_container": self.in_container,
            "choice": self.choice,
            "pickable": list(self.pickable),
            "expected_costs": self.expected_costs,
            "right": self.right,
            "problems": list(self.problems),
            "warnings": list(self.warnings),
        }


def check_decision(case: CanonicalCase, choice: str, expected_costs: dict[str, float]) -> tuple[str, ...]:
    """What is wrong with a decision on a canonical case (empty when it is right).

    Examples
    --------
    >>> from unstack.experiments.canonical_scenes import build_case
    >>> case = build_case("tower_beside_free", seed=0)
    >>> check_decision(case, "bottom", {"bottom": 0.1, "middle": 1.0, "top": 0.0, "free": 0.0})[0]
    "picked 'bottom', which holds up 2 boxes"
    """
    problems = []
    if choice not in case.pickable:
        problems.append(f"picked {choice!r}, which holds up {case.holds.get(choice, 0)} boxes")
    for box, held in case.holds.items():
        if expected_costs[box] < HOLD_SHARE * held:
            problems.append(f"EC({box}) = {expected_costs[box]:.3f} < {HOLD_SHARE * held:.2f} (holds up {held})")
    for box in case.pickable:
        if expected_costs[box] >= FREE_MAX:
            problems.append(f"EC({box}) = {expected_costs[box]:.3f} >= {FREE_MAX} although it holds up nothing")
    return tuple(problems)


def run_suite(
    decide: Callable[[Scene], Any],
    *,
    kinds: Sequence[str] | None = None,
    seeds: Sequence[int] = (0,),
    clouds: Sequence[str] = CLOUDS,
    progress: Callable[[int, int], None] | None = None,
) -> list[SuiteResult]:
    """Decide every canonical scene of ``kinds`` x ``seeds`` x ``clouds`` and check the decisions.

    Parameters
    ----------
    decide : callable
        Scene -> :class:`~unstack.reasoner.decision.Decision` (for example
        ``lambda scene: unstack.decide(scene, seed=0)``).
    kinds, seeds, clouds
        What to run (all kinds by default).
    progress : callable, optional
        Called with (done, total) after each decision.
    """
    kinds = list(CANONICAL_KINDS) if kinds is None else list(kinds)
    tasks = [(kind, seed, cloud) for kind in kinds for seed in seeds for cloud in clouds]
    results = []
    for done, (kind, seed, cloud) in enumerate(tasks, start=1):
        case = build_case(kind, seed=seed)
        scene = canonical_scene(case, cloud=cloud, seed=seed)
        decision = decide(scene)
        costs = {box: float(cost) for box, cost in zip(decision.objects, decision.expected_costs, strict=True)}
        results.append(
            SuiteResult(
                kind=kind,
                seed=seed,
                cloud=cloud,
                in_container=case.in_container,
                choice=decision.choice,
                pickable=case.pickable,
                expected_costs=costs,
                problems=check_decision(case, decision.choice, costs),
                warnings=tuple(getattr(decision, "warnings", ())),
            )
        )
        if progress is not None:
            progress(done, len(tasks))
    return results
