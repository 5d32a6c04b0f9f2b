"""Statics' rule for upright boxes against physics: a carton past the edge of the box it stands on.

Each scene is a carton standing upright on a short box, its centre a drawn distance past the
short box's edge (or inside it), and a tall box whose side it touches on the overhanging side
(2 mm away): past the edge the tall box keeps the carton from tipping, inside it the carton
stands alone. The truth comes from the physics engine (pybullet: the boxes as placed, each
taken away in turn, as :func:`unstack.experiments.generalisation.physical_check` does); a scene
that moves with nothing taken away is dropped. The robot's view: a surface cloud from the door
(3 mm depth noise) and the boxes' poses, exact or each off by a drawn error (a detector's).
For each kind this prints how often the default decision picks a box whose removal moves
nothing, with statics and without (``statics=False``), how many scenes got a finding that is
wrong (its supporter's removal does not move the box said to be held), and the right picks by
how far the carton's centre lies past the edge.

Kinds: ``past`` (0-12 cm past, poses exact), ``past-yawed`` (the carton turned 20-45 degrees),
``past-off`` (every pose off by 5 mm, sd in x and y, half that in z), ``inside-off`` (the
centre 0-4 cm inside the edge, poses off by 1.5 cm sd: no finding is right there).

Usage::

    python benchmarks/statics_overhangs.py --scenes 30 --seed 0
"""

from __future__ import annotations

import argparse
import warnings
from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation

import unstack
from unstack.geometry import box_corners
from unstack.scene import Box, Scene
from unstack.understanding.clouds import surface_cloud
from unstack.understanding.statics import tip_supports

#: Kind -> (the centre's distance past the edge drawn in this range (metres), yaw range (degrees), pose error sd).
KINDS = {
    "past": ((0.0, 0.12), (0.0, 0.0), 0.0),
    "past-yawed": ((0.0, 0.12), (20.0, 45.0), 0.0),
    "past-off": ((0.0, 0.12), (0.0, 0.0), 0.005),
    "inside-off": ((-0.04, 0.0), (0.0, 0.0), 0.015),
}
#: Bands of the centre's distance past the edge (metres) the right picks are counted in.
BANDS = (0.0, 0.01, 0.02, 0.03, 0.04, 0.12)


def draw_boxes(rng: np.random.Generator, beyond: float, yaw_deg: float) -> list[Box]:
    """The tall box, the short box and the carton, its centre ``beyond`` metres past the short box's edge."""
    short = Box("short", [0.4, 0.3, 0.2], [1.3, -0.45, 0.1])
    turned = Rotation.from_euler("z", yaw_deg, degrees=True).as_quat()
    carton = Box("carton", [0.4, 0.5, 0.25], [1.3, -0.3 + beyond, 0.326], turned)
    reach = float(box_corners(carton)[:, 1].max())
    height = float(rng.uniform(0.6, 0.9))
    tall = Box("tall", [0.4, 0.4, height], [1.3, reach + 0.202, height / 2 + 0.001])
    return [tall, short, carton]


def removal_labels(boxes: list[Box]) -> np.ndarray | None:
    """``labels[i, j]``: taking box i away moves box j (None when the boxes move as placed)."""
    from unstack.sim.ground_truth import removal_responses, support_labels
    from unstack.sim.settings import GroundTruthSettings, SimulationSettings
    from unstack.sim.world import PhysicsWorld

    truth = GroundTruthSettings()
    with PhysicsWorld(SimulationSettings(boxes=(1, 1)), door=False) as world:
        for box in boxes:
            world.add_box(box.size, box.position, box.orientation_xyzw, mass=5.0)
        response = removal_responses(world, truth)
    if response.baseline_displacement > truth.displacement_threshold:
        return None
    labels: np.ndarray = support_labels(
        response.displacement,
        response.rotation_deg,
        displacement_threshold=truth.displacement_threshold,
        rotation_threshold_deg=truth.rotation_threshold_deg,
    )
    return labels


def seen(box: Box, rng: np.random.Generator, error: float) -> Box:
    """The box as a detector reports it: its position off by ``error`` (sd) in x and y, half that in z."""
    offset = rng.normal(0.0, error, 3) * [1.0, 1.0, 0.5]
    return Box(box.id, box.size, box.position + offset, box.orientation_xyzw)


def run_kind(kind: str, scenes: int, rng: np.random.Generator) -> dict[str, Any]:
    """Draw ``scenes`` scenes of ``kind``; count the stable ones, right picks and wrong findings."""
    (low, high), (yaw_low, yaw_high), error = KINDS[kind]
    counts: dict[str, Any] = {"stable": 0, "statics": 0, "model": 0, "wrong_finding": 0}
    counts["bands"] = np.zeros((len(BANDS) - 1, 3), dtype=int)  # scenes, right with statics, without
    for _ in range(scenes):
        beyond = float(rng.uniform(low, high))
        boxes = draw_boxes(rng, beyond, float(rng.uniform(yaw_low, yaw_high)))
        labels = removal_labels(boxes)
        if labels is None:
            continue
        ids = [box.id for box in boxes]
        cloud = surface_cloud(
            boxes, viewpoint=(-1.8, 0.0, 1.6), spacing=0.02, depth_noise=0.003, seed=int(rng.integers(2**31))
        )
        scene = Scene([seen(box, rng, error) for box in boxes], cloud, ids)
        found = tip_supports(scene)
        right = {}
        for with_statics in (True, False):
            pick = ids.index(unstack.decide(scene, seed=0, statics=with_statics).choice)
            right[with_statics] = not labels[pick].any()
        counts["stable"] += 1
        counts["statics"] += right[True]
        counts["model"] += right[False]
        counts["wrong_finding"] += any(not labels[ids.index(f.supporter), ids.index(f.held)] for f in found)
        band = int(np.searchsorted(BANDS, beyond, side="right")) - 1
        if 0 <= band < len(BANDS) - 1:
            counts["bands"][band] += [1, right[True], right[False]]
    return counts


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--scenes", type=int, default=30, help="scenes drawn per kind (default: %(default)s)")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--kinds", nargs="+", choices=list(KINDS), default=list(KINDS))
    args = parser.parse_args()
    warnings.simplefilter("ignore")  # statics' and the checks' warnings are counted, not printed
    print(f"python benchmarks/statics_overhangs.py --scenes {args.scenes} --seed {args.seed}")
    print("| kind | stable scenes | pick moves nothing, statics / model alone | scenes with a wrong finding |")
    print("|---|---:|---:|---:|")
    bands: dict[str, np.ndarray] = {}
    for kind in args.kinds:
        counts = run_kind(kind, args.scenes, np.random.default_rng([args.seed, list(KINDS).index(kind)]))
        print(
            f"| {kind} | {counts['stable']} | {counts['statics']} / {counts['model']} | {counts['wrong_finding']} |",
            flush=True,
        )
        bands[kind] = counts["bands"]
    past = [kind for kind in args.kinds if kind.startswith("past")]
    if past:
        print("\n| centre past the edge | " + " | ".join(past) + " |")
        print("|---|" + "---:|" * len(past))
        for band in range(len(BANDS) - 1):
            cells = [f"{bands[kind][band, 1]} / {bands[kind][band, 2]} of {bands[kind][band, 0]}" for kind in past]
            print(f"| {100 * BANDS[band]:.0f}-{100 * BANDS[band + 1]:.0f} cm | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()
