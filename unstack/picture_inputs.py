"""What a picture of a decision needs from the library: the decision's numbers and the camera.

``unstack render`` and ``unstack view`` draw with :mod:`unstack.pictures`, which imports only the
data model. The composition above it lives here: a stored decision read back, or a decision
(and a plan's order) made now, as :class:`~unstack.pictures.values.DecisionValues`; and the
camera of the sensor that scanned a simulated scene.

Examples
--------
>>> import unstack
>>> values = decision_values(unstack.Supports(["top", "bottom"], [[0, 0.1], [0.9, 0]]))
>>> values.choice, values.order
('top', ())
>>> scene_camera(unstack.load("examples/pile5.scene.json")).position
(-2.8, 0.0, 1.3)
"""

from __future__ import annotations

from typing import Any

from unstack.errors import UnstackError
from unstack.scene import Scene
from unstack.supports import Supports

__all__ = ["decision_values", "scene_camera"]


def decision_values(
    loaded: Scene | Supports,
    decision_file: str | None = None,
    *,
    with_plan: bool = False,
    model: Any = None,
    seed: int | None = 0,
) -> Any:
    """The decision to show: read from ``decision_file``, or decided (and planned) now.

    Parameters
    ----------
    loaded : Scene or Supports
    decision_file : str, optional
        A stored ``unstack.decision/1`` file; its boxes must be those of ``loaded``.
    with_plan : bool
        Plan the whole unloading order (not with ``decision_file``).
    model, seed
        For deciding now (:func:`unstack.api.decide`, :func:`unstack.api.plan`).

    Returns
    -------
    DecisionValues
    """
    import unstack
    from unstack.pictures.values import DecisionValues, read_decision_values

    if decision_file is not None:
        if with_plan:
            raise UnstackError("--plan decides the unloading order itself; it does not combine with --decision")
        if model is not None:
            raise UnstackError("--model decides with that model; a stored --decision was decided already")
        values = read_decision_values(decision_file)
        decided = loaded.detected if isinstance(loaded, Scene) else loaded.objects
        values.check_boxes(loaded.box_ids if isinstance(loaded, Scene) else loaded.objects, loaded.source)
        if set(values.objects) != set(decided):
            verb = "detects" if isinstance(loaded, Scene) else "holds"
            raise UnstackError(
                f"{values.source}: the decision's boxes are not the boxes {loaded.source} {verb} "
                f"({len(values.objects)} against {len(decided)}): not this scene's decision"
            )
        return values
    if with_plan:
        result = unstack.plan(loaded, model=model, seed=seed)
        return DecisionValues.from_decision(result.steps[0].decision, order=result.order, source=loaded.source)
    return DecisionValues.from_decision(unstack.decide(loaded, model=model, seed=seed), source=loaded.source)


def scene_camera(scene: Scene) -> Any:
    """The sensor that scanned a simulated scene, as a :class:`~unstack.pictures.camera.Camera`
    (the default camera for a scene without simulation settings)."""
    from unstack.pictures.camera import Camera
    from unstack.sim.settings import scene_settings

    settings = scene_settings(scene)
    if settings is None:
        return Camera()
    sensor = settings.sensor
    return Camera(
        position=(float(sensor.position[0]), float(sensor.position[1]), float(sensor.position[2])),
        target=(float(sensor.target[0]), float(sensor.target[1]), float(sensor.target[2])),
        vertical_fov_deg=sensor.vertical_fov_deg,
        width=sensor.width,
        height=sensor.height,
    )
