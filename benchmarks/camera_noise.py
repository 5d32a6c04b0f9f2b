"""Camera fits under depth noise: simulated piles rendered as camera files, noise added to the depth.

Each pile of each data set is rendered as :func:`unstack.sim.camera_view.camera_view` hands it
over (exact depth), noise is drawn onto every reading, and
:func:`unstack.camera.scene_from_depth` builds the scene back with the data set's carton sizes.
Per mask: the box's true tilt, whether a box was fitted and from which face, the position error
and the axis error (:func:`unstack.geometry.axis_error_deg`). Printed per
data set, for upright boxes (true tilt under 5 degrees) and tilted ones apart: boxes fitted,
median position error, the share within 5 cm, median axis error, and how many upright boxes were
fitted tilted (and the other way); and, as a comment line, how far the gravity found is from the
simulator's z at most.

Noise: ``kinect`` draws sigma = 0.0012 + 0.0019 (z - 0.4)^2 metres at depth z (a Kinect-like
sensor: 1.4 cm at 3 m, 2.6 cm at 4 m); a number draws that sigma (metres) everywhere; ``0``
leaves the depth exact. ``--flying SHARE``: that share of the pixels beside a jump of more than
5 cm to a farther neighbour read a random mix of their depth and the neighbour's, as a
time-of-flight sensor's mixed ("flying") pixels do where its own filter is off.

Usage::

    unstack simulate --family stacked --configs 10 --seed 7707 --viewpoint-jitter 0.3 --out piles-stacked
    python benchmarks/camera_noise.py piles-stacked --piles 10 --noise kinect --seed 1
    python benchmarks/camera_noise.py piles-stacked --piles 10 --noise 0 --flying 1 --seed 1
"""

from __future__ import annotations

import dataclasses
import sys
import warnings
from pathlib import Path
from typing import Any

import numpy as np

from benchmarks.script_arguments import data_sets_parser, print_markdown_head

#: Boxes tilted at least this far (degrees) count as tilted.
TILTED_DEG = 5.0


def noisy_depth(depth: np.ndarray, noise: str, rng: np.random.Generator) -> np.ndarray:
    """``depth`` (metres, 0 where no reading) with noise drawn onto every reading."""
    sigma = 0.0012 + 0.0019 * (depth - 0.4) ** 2 if noise == "kinect" else np.full(depth.shape, float(noise))
    return np.where(depth > 0, depth + rng.normal(size=depth.shape) * sigma, 0.0)


#: A neighbour this much farther (metres) makes a depth jump, beside which pixels may fly.
JUMP_M = 0.05


def flying_pixels(noisy: np.ndarray, exact: np.ndarray, share: float, rng: np.random.Generator) -> np.ndarray:
    """``noisy`` with ``share`` of the pixels beside a depth jump (in ``exact``: a 4-neighbour
    :data:`JUMP_M` or more farther) reading a uniform random mix of their depth and the farthest
    such neighbour's; no draw at all when ``share`` is 0 (the tables without flying pixels stay
    as they were)."""
    if share <= 0:
        return noisy
    padded = np.pad(exact, 1, mode="edge")
    farthest = np.max([padded[1:-1, :-2], padded[1:-1, 2:], padded[:-2, 1:-1], padded[2:, 1:-1]], axis=0)
    flying = (farthest - exact > JUMP_M) & (exact > 0) & (rng.random(exact.shape) < share)
    mix = rng.random(exact.shape)
    return np.where(flying, mix * noisy + (1.0 - mix) * farthest, noisy)


def pile_rows(path: Path, noise: str, rng: np.random.Generator, flying: float = 0.0) -> list[dict[str, Any]]:
    """One row per mask of the pile: the truth's tilt and how the fit did."""
    from unstack.camera import scene_from_depth
    from unstack.errors import UnstackError
    from unstack.geometry import axis_error_deg, tilt_deg
    from unstack.scene import load_scene
    from unstack.sim.camera_view import camera_view
    from unstack.sim.settings import SimulationSettings, scene_settings

    scene = load_scene(path)
    settings = scene_settings(scene) or SimulationSettings()
    view = camera_view(scene)
    depth = flying_pixels(noisy_depth(view.depth_m, noise, rng), view.depth_m, flying, rng)
    view = dataclasses.replace(view, depth_m=depth)
    ids = sorted(view.masks)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            built = scene_from_depth(
                view.depth_m, view.intrinsics, view.camera_to_world, [view.masks[box_id] for box_id in ids], ids=ids,
                known_sizes=[tuple(size) for size in settings.box_sizes()], door=[-1.0, 0.0, 0.0],
            )  # fmt: skip
        except UnstackError as error:  # the whole pile refused: every mask unfitted
            print(f"{path}: {error}", file=sys.stderr)
            return [{"tilted": tilt_deg(scene.box(box_id)) >= TILTED_DEG, "fitted": False} for box_id in ids]
    fitted = {item.box.id: item for item in built.fitted}
    rows: list[dict[str, Any]] = [{"gravity_error_deg": built.frame.tilt_deg}]  # the simulator's z is gravity
    for box_id in ids:
        truth = scene.box(box_id)
        row: dict[str, Any] = {"tilted": tilt_deg(truth) >= TILTED_DEG, "fitted": box_id in fitted}
        if box_id in fitted:
            box = fitted[box_id].box
            row.update(face=fitted[box_id].face, position_error_m=float(np.linalg.norm(box.position - truth.position)),
                       axis_error_deg=axis_error_deg(truth.orientation_xyzw, box.orientation_xyzw))  # fmt: skip
        rows.append(row)
    return rows


def summary_cells(rows: list[dict[str, Any]]) -> list[str]:
    """Fitted of masks, median position error, share within 5 cm, median axis error, fitted the other kind."""
    fitted = [row for row in rows if row["fitted"]]
    if not fitted:
        return [f"0 of {len(rows)}", "-", "-", "-", "-"]
    position = np.array([row["position_error_m"] for row in fitted])
    axes = np.array([row["axis_error_deg"] for row in fitted])
    other_kind = sum((row["face"] == "tilted") != row["tilted"] for row in fitted)
    return [
        f"{len(fitted)} of {len(rows)}",
        f"{1000 * np.median(position):.1f} mm",
        f"{np.mean(position < 0.05):.2f}",
        f"{np.median(axes):.1f}",
        str(other_kind),
    ]


def main(argv: list[str]) -> int:
    parser = data_sets_parser(__doc__.splitlines()[0], piles=10)
    parser.add_argument("--noise", default="kinect", help="kinect, or a sigma in metres (default: %(default)s)")
    parser.add_argument("--seed", type=int, default=1, help="seeds the noise (default: %(default)s)")
    parser.add_argument(
        "--flying", type=float, default=0.0, help="share of the pixels beside depth jumps that fly (default: 0)"
    )
    args = parser.parse_args(argv)
    if not 0.0 <= args.flying <= 1.0:
        parser.error(f"--flying: expected a share from 0 to 1, got {args.flying}")
    if args.noise != "kinect":
        try:
            float(args.noise)
        except ValueError:
            parser.error(f"--noise: expected kinect or a sigma in metres, got {args.noise!r}")
    from unstack.dataset_folders import first_configurations

    rng = np.random.default_rng(args.seed)
    print_markdown_head(
        "data set", "boxes", "fitted", "position error, median", "within 5 cm", "axis error, median (deg)",
        "fitted as the other kind", numbers_from=2,
    )  # fmt: skip
    for folder in args.data:
        piles = first_configurations(folder, args.piles)
        rows = [row for path in piles for row in pile_rows(path, args.noise, rng, args.flying)]
        for kind, tilted in (("upright", False), ("tilted", True)):
            chosen = [row for row in rows if row.get("tilted") is tilted]
            print(f"| {Path(folder).name} | {kind} | " + " | ".join(summary_cells(chosen)) + " |", flush=True)
        gravity = [row["gravity_error_deg"] for row in rows if "gravity_error_deg" in row]
        if gravity:
            print(f"<!-- {Path(folder).name}: gravity off by {max(gravity):.1f} degrees at most over {len(gravity)} "
                  "built piles -->", flush=True)  # fmt: skip
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
