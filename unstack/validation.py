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

from unstack.errors import InvalidFile
from unstack.jsonio import Document, read_document, validate_document

__all__ = ["Validated", "check_decision_document", "check_plan_document", "validate"]


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
        detail = f"{len(scene.boxes)} boxes, {len(scene.detected)} detected, {len(scene.points):,} points"
        return Validated(document.source, tag, detail, tuple(scene_warnings(scene)))
    elif tag == "unstack.plan/1":
        check_plan_document(document)
        detail = f"{len(document.data['order'])} boxes in order"
    elif tag == "unstack.dataset/1":
        from unstack.sim.settings import settings_from_json

        settings_from_json(document.data["settings"], source=document.source, path="$.settings")
        detail = f"{document.data['configs']} configurations, seed {document.data['seed']}"
    elif tag == "unstack.payoff/1":
        detail = f"{document.data['consistent_worlds']} consistent worlds"
    else:
        check_decision_document(document)
        detail = f"choice {document.data['choice']!r}"
    return Validated(document.source, tag, detail)


def check_decision_document(document: Document) -> None:
    """What the ``unstack.decision/1`` schema cannot say: one cost (and error) per object, a
    square matrix of them, the choice and the ties among them.

    Raises
    ------
    InvalidFile
        At the first array of another length, or a box that is not one of the objects.

    Examples
    --------
    >>> from pathlib import Path
    >>> from unstack.jsonio import Document
    >>> check_decision_document(Document({"objects": ["a"], "choice": "b", "expected_costs": [0.0],
    ...                                   "marginals": [[0.0]]}, "d.json", Path(".")))
    Traceback (most recent call last):
    ...
    unstack.errors.InvalidFile: d.json: $.choice: expected one of the objects, got 'b'
    """
    data, source = document.data, document.source
    objects = data["objects"]
    n = len(objects)
    for key in ("expected_costs", "expected_cost_errors"):
        if key in data and len(data[key]) != n:
            raise InvalidFile(source, f"$.{key}", f"expected {n} numbers (one per object), got {len(data[key])}")
    marginals = data["marginals"]
    if len(marginals) != n or any(len(row) != n for row in marginals):
        raise InvalidFile(source, "$.marginals", f"expected a {n} x {n} matrix (one row and column per object)")
    known = set(objects)
    if data["choice"] not in known:
        raise InvalidFile(source, "$.choice", f"expected one of the objects, got {data['choice']!r}")
    for index, box in enumerate(data.get("ties", [])):
        if box not in known:
            raise InvalidFile(source, f"$.ties[{index}]", f"expected one of the objects, got {box!r}")


def check_plan_document(document: Document) -> None:
    """What the ``unstack.plan/1`` schema cannot say: the order takes each object once, and
    step ``k`` takes the ``k``-th box of the order from the boxes still in place.

    Raises
    ------
    InvalidFile
        At the first box out of place.
    """
    data, source = document.data, document.source
    order, objects = data["order"], data["objects"]
    if sorted(order) != sorted(objects) or len(set(order)) != len(order):
        raise InvalidFile(source, "$.order", "expected each of the objects once")
    if len(data["steps"]) != len(order):
        raise InvalidFile(source, "$.steps", f"expected {len(order)} steps (one per box of the order)")
    for index, (step, box) in enumerate(zip(data["steps"], order, strict=True)):
        if step["choice"] != box:
            raise InvalidFile(source, f"$.steps[{index}].choice", f"expected {box!r}, the order's box")
        if box not in step["remaining"]:
            raise InvalidFile(source, f"$.steps[{index}].remaining", f"expected the boxes in place to hold {box!r}")
