"""How well each drawn fill of the unseen space matches the hidden boxes: runs kept one by one
(``scaled``) against whole hidden cartons (``cartons``), on the first scan of each pile.

For the first ``--piles`` piles of each data set, the boxes in view are the detected ones
(:func:`unstack.sim.unloading.in_view_scene`, as the physics veto sees them); each fill draws
``--worlds`` hypotheses of the solid unseen space (:func:`unstack.sim.belief.belief_removals`'s
worlds, the same seed). Printed per data set and fill, over every world of every pile:

* precision: the share of the drawn solid (grid points ``--step`` apart) that lies inside a
  box nobody sees (the simulator knows them; a robot does not);
* recall: the share of the hidden boxes' space within reach of the boxes in view
  (:data:`unstack.understanding.hidden_cartons.CARTON_REACH`) and behind the visible surface
  that the drawn solid covers.

Usage::

    python benchmarks/carton_truth.py f30-four f30-stacked f30-mixed --piles 10
"""

from __future__ import annotations

import numpy as np
from occlusion_truth import block_samples
from script_arguments import data_sets_parser, print_markdown_head

from unstack.dataset_folders import require_configurations
from unstack.geometry import points_in_box
from unstack.scene import load_scene
from unstack.sim.belief import belief_settings, container_interior, drawn_worlds
from unstack.sim.unloading import in_view_scene
from unstack.understanding.hidden_cartons import CARTON_REACH
from unstack.understanding.occlusion import occlusion_grid

FILLS = ("scaled", "cartons")


def _inside_any(points: np.ndarray, boxes: list) -> np.ndarray:  # type: ignore[type-arg]
    inside = np.zeros(len(points), dtype=bool)
    for box in boxes:
        inside |= points_in_box(points, box, margin=0.0)
    return inside


def _block_points(blocks: list, step: float) -> np.ndarray:  # type: ignore[type-arg]
    parts = [block_samples(block.center, block.size, step) for block in blocks]
    return np.concatenate(parts) if parts else np.zeros((0, 3))


def _covered(points: np.ndarray, blocks: list) -> np.ndarray:  # type: ignore[type-arg]
    covered = np.zeros(len(points), dtype=bool)
    for block in blocks:
        covered |= np.all(np.abs(points - block.center) <= block.size / 2, axis=1)
    return covered


def truth(data: str, piles: int, worlds: int, step: float) -> dict[str, tuple[float, float]]:
    """Precision and recall of each fill's drawn solid over the first scans of ``piles`` piles."""
    counts = {fill: np.zeros(4) for fill in FILLS}  # solid inside, solid, hidden covered, hidden
    for path in require_configurations(data)[:piles]:
        scene = in_view_scene(load_scene(path))
        settings = belief_settings(scene)
        hidden = [box for box in scene.boxes if box.id not in set(scene.detected)]
        interior = container_interior(settings)
        seen = [scene.box(box_id) for box_id in scene.detected]
        grid = occlusion_grid(
            scene.points, seen, viewpoint=settings.sensor.position, interior=interior, reach=CARTON_REACH
        )
        if grid is None:
            continue
        cells = np.stack(np.meshgrid(*grid.axes, indexing="ij"), axis=-1)[grid.occluded]
        hidden_cells = cells[_inside_any(cells, hidden)]
        for fill in FILLS:
            for blocks in drawn_worlds(scene, settings, fill, 0.2, worlds, np.random.default_rng(0)):
                solid = _block_points(blocks, step)
                counts[fill] += [
                    _inside_any(solid, hidden).sum(),
                    len(solid),
                    _covered(hidden_cells, blocks).sum(),
                    len(hidden_cells),
                ]
    return {fill: (c[0] / max(c[1], 1), c[2] / max(c[3], 1)) for fill, c in counts.items()}


def main() -> None:
    parser = data_sets_parser(__doc__.splitlines()[0], piles=10)
    parser.add_argument("--worlds", type=int, default=4)
    parser.add_argument("--step", type=float, default=0.03)
    args = parser.parse_args()
    print_markdown_head(
        "data", "fill", "precision (drawn solid inside a hidden box)", "recall (hidden space covered)", numbers_from=2
    )
    for data in args.data:
        for fill, (precision, recall) in truth(data, args.piles, args.worlds, args.step).items():
            print(f"| {data} | {fill} | {precision:.3f} | {recall:.3f} |", flush=True)


if __name__ == "__main__":
    main()
