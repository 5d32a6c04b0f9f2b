"""How much of the space the sensor cannot see is boxes: the occlusion fill against the true pile.

For the first scan of the first ``--piles`` piles of each data set, the space the sensor cannot
see next to the detected boxes (:func:`unstack.sim.belief.occlusion_blocks`, the blocks the
``occlusion`` fill makes solid) is sampled on a grid of ``--step`` metres; a sample is
occupied when it lies inside a box the detector did not report (the simulator knows them, a
robot does not). Printed per data set: the occupied share of all samples, of the samples under
a detected box (one stands over them), and of those over the floor only (no detected box
under them). The ``sampled`` fill keeps each run of that space solid with probability
:data:`unstack.sim.belief.OCCUPANCY`, chosen from these shares; the ``scaled`` fill's chance
(:func:`unstack.sim.belief.scaled_occupancy`) is printed beside the true share, pile by pile
averaged. With ``--misses M`` each detected box is dropped from the detected ones with chance
``M`` first (seeded), as a detector that misses boxes would; the space behind a surface no
detected box explains (:func:`unstack.sim.belief.behind_seen_faces`, its first
:data:`unstack.sim.belief.FACE_DEPTH`: what the ``faces`` fill keeps solid) is counted apart.

Usage::

    python benchmarks/occlusion_truth.py f30-four f30-stacked --piles 8
    python benchmarks/occlusion_truth.py d10-four d10-stacked d10-mixed --piles 8 --misses 0.5
"""

from __future__ import annotations

import dataclasses

import numpy as np
from script_arguments import data_sets_parser

from unstack.dataset_folders import require_configurations
from unstack.geometry import bounding_boxes, points_in_box
from unstack.scene import load_scene
from unstack.sim.belief import FACE_DEPTH, behind_seen_faces, occlusion_blocks, scaled_occupancy


def block_samples(center: np.ndarray, size: np.ndarray, step: float) -> np.ndarray:
    """Grid points inside an axis-aligned block, ``step`` apart (its centre when it is thinner)."""
    axes = [
        np.arange(middle - extent / 2 + step / 2, middle + extent / 2, step) if extent > step else np.array([middle])
        for middle, extent in zip(center, size, strict=True)
    ]
    return np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)


def occupancy(data: str, piles: int, step: float, misses: float = 0.0, seed: int = 0) -> dict[str, float]:
    """Occupied shares of the occluded space on the first scan of each pile."""
    occupied_parts, under_parts, faced_parts, scaled, true_shares = [], [], [], [], []
    rng = np.random.default_rng(seed)
    for path in require_configurations(data)[:piles]:
        scene = load_scene(path)
        if misses:
            kept = [box_id for box_id in scene.detected if rng.random() >= misses] or list(scene.detected[:1])
            scene = dataclasses.replace(scene, detected=tuple(kept))
        hidden = [box for box in scene.boxes if box.id not in set(scene.detected)]
        seen = bounding_boxes([scene.box(box_id) for box_id in scene.detected])
        blocks = occlusion_blocks(scene)
        if not blocks:
            continue
        behind = behind_seen_faces(scene, blocks)
        per_block = [block_samples(block.center, block.size, step) for block in blocks]
        samples = np.vstack(per_block)
        faced = np.concatenate(
            [
                (block_points[:, 0] < block.center[0] - block.size[0] / 2 + FACE_DEPTH) & front
                for block_points, block, front in zip(per_block, blocks, behind, strict=True)
            ]
        )
        occupied = np.zeros(len(samples), dtype=bool)
        for box in hidden:
            occupied |= points_in_box(samples, box)
        scaled.append(scaled_occupancy(blocks))
        true_shares.append(float(occupied.mean()))
        faced_parts.append(faced)
        over = np.all((samples[:, None, :2] > seen[None, :, :2]) & (samples[:, None, :2] < seen[None, :, 3:5]), axis=2)
        under = (over & (seen[None, :, 2] > samples[:, None, 2])).any(axis=1)
        occupied_parts.append(occupied)
        under_parts.append(under)
    occupied, under = np.concatenate(occupied_parts), np.concatenate(under_parts)
    faced = np.concatenate(faced_parts)
    return {
        "samples": float(len(occupied)),
        "occupied": float(occupied.mean()),
        "pile_share": float(np.mean(true_shares)),
        "scaled": float(np.mean(scaled)),
        "faced_share": float(faced.mean()),
        "occupied_faced": float(occupied[faced].mean()) if faced.any() else float("nan"),
        "occupied_unfaced": float(occupied[~faced].mean()) if (~faced).any() else float("nan"),
        "under_share": float(under.mean()),
        "occupied_under": float(occupied[under].mean()) if under.any() else float("nan"),
        "occupied_elsewhere": float(occupied[~under].mean()) if (~under).any() else float("nan"),
    }


def main() -> None:
    parser = data_sets_parser(__doc__.splitlines()[0], piles=8)
    parser.add_argument("--step", type=float, default=0.03, help="grid step of the samples (m)")
    parser.add_argument("--misses", type=float, default=0.0, help="chance a detected box is dropped")
    parser.add_argument("--seed", type=int, default=0, help="seeds the misses")
    arguments = parser.parse_args()
    print(
        "data set | samples | occupied | share under a detected box | occupied there | occupied elsewhere | "
        "per pile: true share / scaled fill's chance | behind a seen face: share / occupied there / elsewhere"
    )
    for data in arguments.data:
        shares = occupancy(data, arguments.piles, arguments.step, arguments.misses, arguments.seed)
        print(
            f"{data} | {shares['samples']:.0f} | {shares['occupied']:.3f} | {shares['under_share']:.2f} | "
            f"{shares['occupied_under']:.3f} | {shares['occupied_elsewhere']:.3f} | "
            f"{shares['pile_share']:.3f} / {shares['scaled']:.3f} | {shares['faced_share']:.2f} / "
            f"{shares['occupied_faced']:.3f} / {shares['occupied_unfaced']:.3f}"
        )


if __name__ == "__main__":
    main()
