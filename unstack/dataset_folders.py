"""Data-set folders, read side: the names, the manifest and the finished scene files.

A data set folder (written by :func:`unstack.sim.dataset.simulate_dataset`, read by the
learner and the experiments) holds::

    manifest.json                  unstack.dataset/1: settings, seed, size, versions, statistics
    config-0000.json               unstack.scene/1 (written last: its presence means "done")
    config-0000.points.npy         the point cloud (N x 3 float64)
    config-0000.point_boxes.npy    box index of every point (-1: container)
    timings.jsonl                  CPU seconds per phase and configuration (one line each)

This module belongs to the data model: learning reads data sets through it and never
imports the simulator.

Examples
--------
>>> config_name(7)
'config-0007'
>>> import tempfile
>>> list_configurations(tempfile.mkdtemp())
[]
"""

from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path
from typing import Any

from unstack.errors import UnstackError

__all__ = [
    "DATASET_FORMAT",
    "MANIFEST",
    "TIMINGS",
    "config_name",
    "dataset_digest",
    "first_configurations",
    "list_configurations",
    "read_manifest",
    "require_configurations",
    "scene_digest",
]

DATASET_FORMAT = "unstack.dataset/1"
MANIFEST = "manifest.json"
TIMINGS = "timings.jsonl"


def config_name(index: int) -> str:
    """File stem of configuration ``index`` in a data set folder.

    Examples
    --------
    >>> config_name(12)
    'config-0012'
    """
    return f"config-{index:04d}"


def list_configurations(folder: str | os.PathLike[str]) -> list[Path]:
    """The finished scene files of a data set folder, in index order."""
    return sorted(Path(folder).glob("config-[0-9][0-9][0-9][0-9].json"))


def require_configurations(folder: str | os.PathLike[str]) -> list[Path]:
    """:func:`list_configurations`, or an error naming the folder when it holds none.

    Warns (:class:`UserWarning`) when the folder's manifest lists more configurations than are
    finished: a simulation still running, or stopped, whose finished part would otherwise be
    taken for the whole data set. A manifest that is not a valid ``unstack.dataset/1`` is an
    error.

    Examples
    --------
    >>> require_configurations("/x")
    Traceback (most recent call last):
    ...
    unstack.errors.UnstackError: /x: expected a data set folder with config-NNNN.json scene files, found none
    """
    files = list_configurations(folder)
    if not files:
        raise UnstackError(f"{folder}: expected a data set folder with config-NNNN.json scene files, found none")
    manifest = read_manifest(folder)  # a manifest there must be one (refused in one line, not passed over)
    listed = None if manifest is None else manifest["configs"]
    if listed is not None and len(files) < listed:
        import warnings

        warnings.warn(
            f"{folder}: {len(files)} of the {listed} configurations its manifest lists are finished (a simulation "
            "still running, or stopped); only those are read",
            stacklevel=2,
        )
    return files


def first_configurations(folder: str | os.PathLike[str], count: int | None, noun: str = "piles") -> list[Path]:
    """The first ``count`` configurations of a data set folder (:func:`require_configurations`;
    ``None``: all), with a warning when it holds fewer than asked for (all are used).

    Examples
    --------
    >>> import warnings, tempfile
    >>> folder = Path(tempfile.mkdtemp())
    >>> _ = (folder / "config-0000.json").write_text("{}")
    >>> with warnings.catch_warnings(record=True) as said:
    ...     warnings.simplefilter("always")
    ...     len(first_configurations(folder, 5))
    1
    >>> str(said[0].message).endswith("5 piles asked for, the data set has 1: all 1 are used")
    True
    """
    files = require_configurations(folder)
    if count is not None and count > len(files):
        import warnings

        warnings.warn(
            f"{folder}: {count} {noun} asked for, the data set has {len(files)}: all {len(files)} are used",
            stacklevel=2,
        )
    return files if count is None else files[:count]


def read_manifest(folder: str | os.PathLike[str]) -> dict[str, Any] | None:
    """The folder's manifest (validated as ``unstack.dataset/1``), or ``None`` if it has none."""
    path = Path(folder) / MANIFEST
    if not path.exists():
        return None
    from unstack.jsonio import read_document, validate_document

    document = read_document(path)
    validate_document(document, [DATASET_FORMAT])
    return document.data


def scene_digest(path: Path) -> str:
    """SHA-256 of a scene file with the files it names (its cloud, its points' box labels): what a
    pile's stored result rests on, so a changed cloud is run again.

    Examples
    --------
    >>> len(scene_digest(Path("examples/pile5.scene.json")))
    64
    """
    digest = hashlib.sha256(path.read_bytes())
    try:
        data = json.loads(path.read_text())
    except (OSError, ValueError):  # no scene: the bytes alone
        return digest.hexdigest()
    metadata = data.get("metadata") if isinstance(data, dict) else None
    named = [data.get("points_file") if isinstance(data, dict) else None]
    named.append(metadata.get("point_boxes_file") if isinstance(metadata, dict) else None)
    for name in named:
        if isinstance(name, str) and (path.parent / name).is_file():
            digest.update((path.parent / name).read_bytes())
    return digest.hexdigest()


def dataset_digest(files: list[Path]) -> str:
    """SHA-256 of a data set's configurations (:func:`scene_digest` of each, by name): two runs on
    one data set agree on it wherever each was started from.

    Examples
    --------
    >>> dataset_digest([Path("examples/pile5.scene.json")]) == dataset_digest([Path("./examples/pile5.scene.json")])
    True
    """
    digest = hashlib.sha256()
    for path in sorted(files, key=lambda file: file.name):
        digest.update(f"{path.name}:{scene_digest(path)};".encode())
    return digest.hexdigest()
