"""What a box detector reports: the true boxes with the position and yaw errors of a real detector.

Used to train on boxes as a detector would give them (``unstack train --pose-noise``) and
to hand a closed-loop unloading policy boxes as a robot's detector would
(:func:`unstack.sim.unloading.unload_container`).

Examples
--------
>>> import numpy as np
>>> from unstack.scene import Box
>>> moved = detector_poses([Box("a", [0.4, 0.4, 0.3], [1.0, 0.0, 0.15])], 0.01, np.random.default_rng(0))
>>> bool(np.linalg.norm(moved[0].position - [1.0, 0.0, 0.15]) < 0.1)
True
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from unstack.scene import Box

__all__ = ["YAW_PER_METRE", "detector_poses"]

#: Yaw error of :func:`detector_poses` per metre of position error (degrees per metre).
YAW_PER_METRE = 200.0


def detector_poses(boxes: Sequence[Box], noise: float, rng: np.random.Generator) -> list[Box]:
    """The boxes as a detector might report them: normal position errors of ``noise`` metres
    across (x, y) and half of it vertically, yaw errors of ``YAW_PER_METRE * noise`` degrees.

    Examples
    --------
    >>> moved = detector_poses([Box("a", [0.4, 0.4, 0.3], [1.0, 0.0, 0.15])], 0.01, np.random.default_rng(0))
    >>> bool(np.linalg.norm(moved[0].position - [1.0, 0.0, 0.15]) < 0.1)
    True
    """
    from scipy.spatial.transform import Rotation

    result = []
    for box in boxes:
        shift = rng.normal(0.0, noise, size=3) * [1.0, 1.0, 0.5]
        yaw = Rotation.from_euler("z", rng.normal(0.0, YAW_PER_METRE * noise), degrees=True)
        orientation = (yaw * Rotation.from_quat(np.array(box.orientation_xyzw))).as_quat()  # a writeable copy
        result.append(Box(box.id, box.size, box.position + shift, orientation, box.mass))
    return result
