"""The generalisation suite: canonical scenes, two kinds of cloud, the default decision checked.

Every canonical scene (:mod:`unstack.experiments.canonical_scenes`) is scanned twice: by the
project's range sensor (pybullet's renderer from the door, :mod:`unstack.sim.sensor`) and by
:func:`unstack.understanding.clouds.surface_cloud` (faces sampled at another density, from a moved
viewpoint, with depth noise and missing faces). A decision is *right* when its choice is a
pickable box (it holds up nothing) and its expected costs respect the scene's bounds: a box
that carries a load of k boxes (a box resting on m boxes weighs 1/m on each, with what rests
on it; see :class:`~unstack.experiments.canonical_scenes.CanonicalCase`) costs at least
``HOLD_SHARE * k``, a pickable box less than :data:`FREE_MAX`.

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

__all__ = [
    "CLOUDS",
    "FREE_MAX",
    "HOLD_SHARE",
    "PICKS",
    "SuiteResult",
    "canonical_scene",
    "check_decision",
    "physical_check",
    "picked",
    "run_suite",
    "suite_figure",
    "summary_rows",
]

#: The two ways a canonical scene is scanned.
CLOUDS = ("sensor", "surface")
#: How the first box is picked from a decision: the default on a scene (the highest free box,
#: :func:`unstack.height_veto.free_highest`), the reasoner's own choice (near ties in expected
#: cost to the box resting highest), the minimum EC (Eq. 12), or the hybrid
#: (:func:`unstack.height_veto.highest_free_box`).
PICKS = ("default", "near-ties", "min-cost", "hybrid")
#: A box that carries a load of k boxes must cost at least this share of k.
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
    from unstack.understanding.clouds import surface_cloud

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
    for box, load in case.load.items():
        if expected_costs[box] < HOLD_SHARE * load:
            problems.append(f"EC({box}) = {expected_costs[box]:.3f} < {HOLD_SHARE * load:.2f} (carries {load:.2f})")
    for box in case.pickable:
        if expected_costs[box] >= FREE_MAX:
            problems.append(f"EC({box}) = {expected_costs[box]:.3f} >= {FREE_MAX} although it holds up nothing")
    return tuple(problems)


def picked(decision: Any, scene: Scene, pick: str) -> Any:
    """``decision`` with its choice made by ``pick`` (a key of :data:`PICKS`); the costs unchanged.

    Examples
    --------
    >>> import numpy as np
    >>> from unstack.reasoner.decision import decide
    >>> from unstack.scene import Box
    >>> from unstack.supports import Supports
    >>> boxes = [Box("tall", [0.4, 0.4, 0.8], [1.0, 0.0, 0.4]), Box("low", [0.4, 0.4, 0.3], [1.0, 0.5, 0.15])]
    >>> scene = Scene(boxes, np.zeros((0, 3)), ["tall", "low"])
    >>> decision = decide(Supports(["tall", "low"], [[0.0, 0.3], [0.0, 0.0]], heights=[0.0, 0.0]))
    >>> picked(decision, scene, "near-ties").choice, picked(decision, scene, "default").choice
    ('low', 'tall')
    """
    import dataclasses

    from unstack.errors import UnstackError
    from unstack.height_veto import free_highest, hybrid_choice
    from unstack.reasoner.decision import choose

    if pick not in PICKS:
        raise UnstackError(f"unknown pick {pick!r}; expected one of {', '.join(PICKS)}")
    if pick == "default":
        return free_highest(decision, scene)
    if pick == "near-ties":
        return decision
    if pick == "min-cost":
        choice, ties = choose(tuple(decision.objects), decision.expected_costs)
        return dataclasses.replace(decision, choice=choice, ties=ties, near_tie_margin=0.0)
    return dataclasses.replace(decision, choice=hybrid_choice(scene, decision))


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


def physical_check(case: CanonicalCase) -> list[str]:
    """Where the case's labels disagree with the physics engine (empty when they agree).

    The boxes are put in pybullet as placed (no settling), each box is taken away in turn
    and the others watched (:func:`unstack.sim.ground_truth.removal_responses`): a box the
    case calls pickable must move nothing, and a box it says holds up others must move at
    least one of them. Boxes that move with nothing taken away make the case unstable.
    """
    from unstack.sim.ground_truth import removal_responses, support_labels
    from unstack.sim.settings import GroundTruthSettings, SimulationSettings
    from unstack.sim.world import PhysicsWorld

    truth = GroundTruthSettings()
    with PhysicsWorld(SimulationSettings(boxes=(1, 1)), door=False) as world:
        for box in case.boxes:
            world.add_box(box.size, box.position, box.orientation_xyzw, mass=5.0)
        response = removal_responses(world, truth)
    problems = []
    if response.baseline_displacement > truth.displacement_threshold:
        problems.append(f"unstable: a box moves {response.baseline_displacement:.3f} m with nothing taken away")
    labels = support_labels(
        response.displacement,
        response.rotation_deg,
        displacement_threshold=truth.displacement_threshold,
        rotation_threshold_deg=truth.rotation_threshold_deg,
    )
    index = {box.id: k for k, box in enumerate(case.boxes)}
    for box_id in case.pickable:
        moved = [case.boxes[j].id for j in np.flatnonzero(labels[index[box_id]])]
        if moved:
            problems.append(f"taking {box_id!r} away moves {moved}")
    for box_id in case.holds:
        if not labels[index[box_id]].any():
            problems.append(f"taking {box_id!r} away moves nothing, although it holds up {case.holds[box_id]}")
    return problems


def summary_rows(results: Sequence[SuiteResult]) -> list[dict[str, Any]]:
    """Per kind and cloud: decisions, right first picks, decisions within every bound."""
    rows: dict[tuple[str, str], dict[str, Any]] = {}
    for result in results:
        row = rows.setdefault(
            (result.kind, result.cloud),
            {"kind": result.kind, "cloud": result.cloud, "scenes": 0, "right_pick": 0, "right": 0},
        )
        row["scenes"] += 1
        row["right_pick"] += result.choice in result.pickable
        row["right"] += result.right
    return list(rows.values())


def _draw_box(axes: Any, box: Any, colour: str, alpha: float, hatch: bool) -> None:
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    from unstack.geometry import BOX_FACES, box_corners

    corners = box_corners(box)
    collection = Poly3DCollection(
        [corners[list(face)] for face in BOX_FACES], facecolor=colour, edgecolor="black", alpha=alpha, linewidths=0.6,
        linestyles="--" if hatch else "-",
    )  # fmt: skip
    axes.add_collection3d(collection)


def suite_figure(cases: Sequence[tuple[CanonicalCase, SuiteResult]], output: str) -> None:
    """One small 3-D view per case: the chosen box red, the other pickable boxes green, boxes
    that hold up others grey, undetected boxes dashed and pale. Written atomically (PNG or SVG)."""
    import math

    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from unstack.plotting import save_figure

    columns = 4
    rows = math.ceil(len(cases) / columns)
    figure = Figure(figsize=(3.2 * columns, 3.0 * rows), layout="constrained")
    FigureCanvasAgg(figure)
    for number, (case, result) in enumerate(cases):
        axes = figure.add_subplot(rows, columns, number + 1, projection="3d")
        for box in case.boxes:
            detected = box.id in case.detected
            colour = "tab:red" if box.id == result.choice else "tab:green" if box.id in case.pickable else "0.6"
            _draw_box(axes, box, colour if detected else "0.9", 0.85 if detected else 0.25, not detected)
        corners = np.vstack([np.array([b.position - b.size, b.position + b.size]) for b in case.boxes])
        low, high = corners.min(axis=0), corners.max(axis=0)
        span = float(max(high - low)) / 2
        centre = (low + high) / 2
        axes.set_xlim(centre[0] - span, centre[0] + span)
        axes.set_ylim(centre[1] - span, centre[1] + span)
        axes.set_zlim(0, 2 * span)
        axes.view_init(elev=18, azim=-150)
        axes.set_axis_off()
        verdict = "right" if result.right else "WRONG" if result.choice not in result.pickable else "bound missed"
        cost = result.expected_costs[result.choice]
        axes.set_title(f"{case.kind.replace('_', ' ')}\npick {result.choice} (EC {cost:.2f}): {verdict}", fontsize=9)
    save_figure(figure, output)
