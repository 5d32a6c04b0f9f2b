"""Checking a file: its schema, and what a schema cannot say (ids, matrices, hard evidence).

Examples
--------
>>> import pathlib, tempfile
>>> from unstack.supports import Supports
>>> file = pathlib.Path(tempfile.mkdtemp()) / "pair.json"
>>> Supports(["a", "b"], [[0, 0.3], [0.6, 0]]).save(file)
>>> validate(file).detail
'2 objects'
"""

from __future__ import annotations

import os
from dataclasses import dataclass

from unstack.checks import check_decision_document, check_payoff_document, check_plan_document, counted
from unstack.jsonio import read_document, validate_document

__all__ = ["Validated", "validate"]


@dataclass(frozen=True)
class Validated:
    """A valid file: where it came from, its format tag and a one-line summary.

    Attributes
    ----------
    source : str
        The file name as given (``<stdin>`` for ``"-"``).
    format : str
        Its ``format`` tag, such as ``unstack.scene/1``.
    detail : str
        What it holds, such as ``5 objects``.
    warnings : tuple of str
        What is doubtful about a valid scene (:func:`unstack.understanding.plausibility.scene_warnings`).
    """

    source: str
    format: str
    detail: str
    warnings: tuple[str, ...] = ()


def validate(path: str | os.PathLike[str]) -> Validated:
    """Check any unstack document as deeply as the library can without deciding.

    Supports and scenes are built (ids, matrices, poses, the point cloud); the hard
    evidence of support probabilities (exactly 0 or 1) must admit a transitive world.

    Parameters
    ----------
    path : str or path-like
        A supports, scene, decision, plan or data-set manifest file; ``"-"`` reads stdin.

    Returns
    -------
    Validated

    Raises
    ------
    InvalidFile
        The file is unreadable, not JSON, of an unknown format or against its schema.
    NoConsistentWorld
        Its hard evidence contradicts transitivity (the message names the file).

    Examples
    --------
    >>> validate("examples/stack5.supports.json").format
    'unstack.supports/1'
    """
    document = read_document(path)
    tag = validate_document(document)
    if tag == "unstack.supports/1":
        from unstack.reasoner.pruning import hard_evidence
        from unstack.supports import Supports

        supports = Supports.from_document(document)
        hard_evidence(supports)
        detail = f"{supports.n_objects} objects"
    elif tag == "unstack.scene/1":
        from unstack.scene import Scene
        from unstack.sim.settings import scene_settings
        from unstack.understanding.plausibility import scene_warnings

        scene = Scene.from_document(document)
        scene_settings(scene)
        if "container" in scene.metadata:  # the physics veto's container, checked as the veto checks it
            from unstack.physics_veto import world_settings

            world_settings(scene)
        detail = (
            f"{counted(len(scene.boxes), 'box', 'boxes')}, {len(scene.detected)} detected, "
            f"{counted(len(scene.points), 'point')}"
        )
        return Validated(document.source, tag, detail, tuple(scene_warnings(scene)))
    elif tag == "unstack.plan/1":
        check_plan_document(document)
        detail = f"{len(document.data['order'])} boxes in order"
    elif tag == "unstack.dataset/1":
        from unstack.sim.settings import settings_from_json

        settings_from_json(document.data["settings"], source=document.source, path="$.settings")
        detail = f"{document.data['configs']} configurations, seed {document.data['seed']}"
    elif tag == "unstack.payoff/1":
        check_payoff_document(document)
        detail = f"{document.data['consistent_worlds']} consistent worlds"
    else:
        check_decision_document(document)
        detail = f"choice {document.data['choice']!r}"
    return Validated(document.source, tag, detail)
