"""Make ``examples/pile5.scene.json``: a simulated pile whose point cloud came from the range sensor,
with five detected boxes (an ISet rich in support relations) and the ground truth.

Run from the repository root (needs the ``sim`` extra)::

    python examples/make_pile5_scene.py

The pile is configuration 0 of ``unstack simulate --seed 2026`` with the default settings but a
320 x 240 sensor (a smaller file); the cloud is stored as float32.
"""

from __future__ import annotations

import itertools
import json
from dataclasses import replace
from pathlib import Path

import numpy as np

from unstack.scene import Scene
from unstack.sim import SensorSettings, SimulationSettings, simulate_configuration

HERE = Path(__file__).resolve().parent


def richest_iset(scene: Scene, size: int) -> list[str]:
    """The ``size`` detectable boxes with the most ground-truth support relations among them."""
    index = {box_id: k for k, box_id in enumerate(scene.box_ids)}
    truth = scene.ground_truth
    assert truth is not None
    related = [box for box in scene.detected if truth[index[box]].sum() + truth[:, index[box]].sum() > 0]
    best: tuple[int, list[str]] = (-1, [])
    for iset in itertools.combinations(sorted(related)[:16], size):
        rows = [index[box] for box in iset]
        count = int(truth[np.ix_(rows, rows)].sum())
        if count > best[0]:
            best = (count, list(iset))
    return best[1]


def main() -> None:
    settings = SimulationSettings(sensor=replace(SensorSettings(), width=320, height=240))
    result = simulate_configuration(settings, seed=2026, index=0)
    scene = result.scene
    iset = richest_iset(scene, 5)
    metadata = {
        "made_by": "python examples/make_pile5_scene.py",
        "simulation": {key: scene.metadata["simulation"][key] for key in ("seed", "index", "versions")},
        "settings": scene.metadata["settings"],
        "complete_set": list(scene.detected),
    }
    example = Scene(scene.boxes, scene.points, iset, scene.ground_truth, metadata)
    cloud = HERE / "pile5.scene.points.npy"
    np.save(cloud, scene.points.astype(np.float32), allow_pickle=False)  # float32: half the file
    document = example.to_dict(points_file=cloud.name)
    (HERE / "pile5.scene.json").write_text(json.dumps(document, indent=1) + "\n")
    print(f"pile5.scene.json: {len(scene.boxes)} boxes, detected {iset}, {len(scene.points):,} points")


if __name__ == "__main__":
    main()
