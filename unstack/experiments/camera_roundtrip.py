"""From the simulator's camera files back to a scene, against the truth (issue 36, part 4).

Each pile of a simulated data set is rendered as a robot's camera would hand it over
(:func:`unstack.sim.camera_view.camera_view`: depth image, intrinsics, pose, one mask per
seen box); :func:`unstack.camera.scene_from_depth` builds the scene back with the data set's
carton sizes as the known sizes. Per fitted box: the position error (metres), the yaw error
(degrees, modulo the top face's symmetry: 180 degrees, 90 for a square top), the axis error
(:func:`unstack.geometry.axis_error_deg`, which a box lying tilted has too), whether the
size is the true one, and the fit's residual; the errors also for the boxes whose face was
seen whole alone (:attr:`unstack.camera.FittedBox.partial`, what the fit itself says). Per
pile: the default decision (:func:`unstack.decide`) on the built scene and on the true poses
(the same boxes detected), and the boxes each pick moves when it is taken out of the true pile
in the physics engine (:func:`unstack.sim.unloading.execute_unloading`).

Examples
--------
>>> round(yaw_error_deg(np.array([0, 0, 0, 1.0]), np.array([0, 0, np.sin(np.pi / 2), np.cos(np.pi / 2)]), False), 6)
0.0
"""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from unstack.experiments.dispatch import run_unordered
from unstack.parameters import COUNT, JOBS, validate_params

__all__ = ["TILTED_DEG", "camera_roundtrip", "yaw_error_deg"]

#: Boxes lying tilted at least this far from standing on a face (degrees) are reported apart.
TILTED_DEG = 5.0


def yaw_error_deg(truth_xyzw: np.ndarray, fitted_xyzw: np.ndarray, square_top: bool) -> float:
    """Angle between the two boxes' long top edges, modulo the top's symmetry (degrees)."""
    from unstack.geometry import rotation_matrix

    def heading(quaternion: np.ndarray) -> float:
        rotation = rotation_matrix(np.asarray(quaternion, dtype=np.float64))
        return float(np.arctan2(rotation[1, 0], rotation[0, 0]))

    period = np.pi / 2 if square_top else np.pi
    difference = np.mod(heading(truth_xyzw) - heading(fitted_xyzw), period)
    return float(np.degrees(min(difference, period - difference)))


def _long_edge_quaternion(box: Any) -> np.ndarray:
    """The box's orientation turned so its local x is its longest horizontal edge (for yaw comparisons)."""
    from unstack.geometry import rotation_matrix

    rotation = rotation_matrix(box.orientation_xyzw)
    horizontal = [axis for axis in range(3) if axis != int(np.argmax(np.abs(rotation[2])))]
    longest = max(horizontal, key=lambda axis: box.size[axis])
    direction = rotation[:, longest]
    yaw = np.arctan2(direction[1], direction[0])
    return np.array([0.0, 0.0, np.sin(yaw / 2), np.cos(yaw / 2)])


def _roundtrip_pile(path: Path, number: int, model: Any, samples: int) -> tuple[int, dict[str, Any]]:
    import warnings

    import unstack
    from unstack.camera import scene_from_depth
    from unstack.geometry import axis_error_deg, tilt_deg
    from unstack.scene import Scene, load_scene
    from unstack.sim.camera_view import camera_view
    from unstack.sim.settings import SimulationSettings, scene_settings
    from unstack.sim.unloading import execute_unloading

    scene = load_scene(path)
    settings = scene_settings(scene) or SimulationSettings()
    view = camera_view(scene)
    ids = sorted(view.masks)
    with warnings.catch_warnings(record=True) as doubts:  # said again below, naming the pile
        warnings.simplefilter("always")
        built = scene_from_depth(
            view.depth_m, view.intrinsics, view.camera_to_world, [view.masks[box_id] for box_id in ids], ids=ids,
            known_sizes=[tuple(size) for size in settings.box_sizes()], door=[-1.0, 0.0, 0.0],
        )  # fmt: skip
    for doubt in doubts:
        warnings.warn(f"{path.name}, built from its camera view: {doubt.message}", stacklevel=2)
    boxes = []
    for item in built.fitted:
        truth = scene.box(item.box.id)
        true_size = np.sort(truth.size)
        square = bool(np.isclose(np.sort(truth.size)[-1], np.sort(truth.size)[-2]))
        boxes.append({
            **item.to_dict(),
            "position_error_m": float(np.linalg.norm(item.box.position - truth.position)),
            "yaw_error_deg": yaw_error_deg(_long_edge_quaternion(truth), _long_edge_quaternion(item.box), square),
            "axis_error_deg": axis_error_deg(truth.orientation_xyzw, item.box.orientation_xyzw),
            "true_tilt_deg": tilt_deg(truth),
            "size_right": bool(np.allclose(np.sort(item.box.size), true_size, atol=1e-6)),
        })  # fmt: skip
    detected = [item.box.id for item in built.fitted]
    truth_scene = Scene(scene.boxes, scene.points, detected, metadata=scene.metadata, source=scene.source)
    choices, moved = {}, {}
    for name, seen in (("truth", truth_scene), ("camera", built.scene)):
        with warnings.catch_warnings():  # the built scenes' doubts are the fit's, reported above
            warnings.simplefilter("ignore")
            choices[name] = str(unstack.decide(seen, model=model, samples=samples, seed=number).choice)
        moved[name] = list(execute_unloading(scene, [choices[name]]).steps[0].moved)
    return number, {"scene": path.name, "tilt_deg": built.frame.tilt_deg, "boxes": boxes,
                    "duplicates": built.duplicates, "unfitted": built.unfitted,
                    "masks": len(ids), "choices": choices, "moved": moved,
                    "warnings": [str(doubt.message) for doubt in doubts]}  # fmt: skip


@validate_params({"piles": COUNT, "samples": COUNT, "n_jobs": JOBS})
def camera_roundtrip(
    data_dir: str | os.PathLike[str],
    model: Any,
    *,
    piles: int = 2,
    samples: int = 1536,
    n_jobs: int = 1,
    progress: Callable[[int, int], None] | None = None,
) -> dict[str, Any]:
    """Render, rebuild and compare the first ``piles`` piles; the summary and every box.

    Returns
    -------
    dict
        ``summary``: fitted boxes, median and 90th-percentile position, yaw and axis errors (the
        last also for the boxes lying tilted :data:`TILTED_DEG` or more in the pile), share
        of sizes right, median residual, share of piles whose decision on the built scene is
        the one on the true poses, and for each of the two (``camera``, ``truth``) the share of
        piles whose pick moves nothing and the boxes it moves per pile; ``piles``: every box of
        every pile, the picks and the boxes each moved.
    """
    from unstack.dataset_folders import first_configurations

    files = first_configurations(data_dir, piles)
    results: list[dict[str, Any] | None] = [None] * len(files)
    tasks = [(path, number, model, samples) for number, path in enumerate(files)]
    if progress is not None:
        progress(0, len(files))
    for number, result in run_unordered(_roundtrip_pile, tasks, n_jobs=n_jobs):
        results[number] = result
        if progress is not None:
            progress(sum(item is not None for item in results), len(files))
    done = [result for result in results if result is not None]
    boxes = [box for result in done for box in result["boxes"]]
    position = np.array([box["position_error_m"] for box in boxes])
    yaw = np.array([box["yaw_error_deg"] for box in boxes])
    whole = np.array([not box["partial"] for box in boxes], dtype=bool)
    tilted = np.array([box["true_tilt_deg"] >= TILTED_DEG for box in boxes], dtype=bool)
    axes = np.array([box["axis_error_deg"] for box in boxes])
    summary = {
        "piles": len(done),
        "masks": int(sum(result["masks"] for result in done)),
        "boxes": len(boxes),
        "position_error_m_median": float(np.median(position)),
        "position_error_m_p90": float(np.percentile(position, 90)),
        "yaw_error_deg_median": float(np.median(yaw)),
        "yaw_error_deg_p90": float(np.percentile(yaw, 90)),
        "axis_error_deg_median": float(np.median(axes)),
        "axis_error_deg_p90": float(np.percentile(axes, 90)),
        "tilted_boxes": int(tilted.sum()),
        "tilted_position_error_m_median": float(np.median(position[tilted])) if tilted.any() else None,
        "tilted_position_error_m_p90": float(np.percentile(position[tilted], 90)) if tilted.any() else None,
        "tilted_axis_error_deg_median": float(np.median(axes[tilted])) if tilted.any() else None,
        "whole_boxes": int(whole.sum()),
        "whole_position_error_m_median": float(np.median(position[whole])) if whole.any() else None,
        "whole_position_error_m_p90": float(np.percentile(position[whole], 90)) if whole.any() else None,
        "whole_yaw_error_deg_p90": float(np.percentile(yaw[whole], 90)) if whole.any() else None,
        "size_right_share": float(np.mean([box["size_right"] for box in boxes])),
        "residual_m_median": float(np.median([box["residual_m"] for box in boxes])),
        "top_faces_share": float(np.mean([box["face"] == "top" for box in boxes])),
        "same_decision_share": float(
            np.mean([result["choices"]["truth"] == result["choices"]["camera"] for result in done])
        ),
        **{
            f"{name}_pick_moved_nothing_share": float(np.mean([not result["moved"][name] for result in done]))
            for name in ("camera", "truth")
        },
        **{
            f"{name}_pick_boxes_moved_mean": float(np.mean([len(result["moved"][name]) for result in done]))
            for name in ("camera", "truth")
        },
    }
    return {"data": str(data_dir), "summary": summary, "piles": done}
