"""Training examples from simulated scenes (§V-A): ISets of detected boxes, every ordered pair.

For each configuration of a data set, ``isets`` random ISets of ``r`` boxes are drawn from
its detected boxes (the complete set 𝔆; scenes with fewer than ``r + 1`` detected boxes give
ISets of all but one, as an ISet is a strict subset), and every ordered pair (X, Y) of an
ISet gives one example: ``F_XY`` and the ground-truth label SUPP(X, Y).

Examples
--------
>>> from unstack.scene import Box, Scene
>>> boxes = [Box(f"b{k}", [0.4, 0.3, 0.3], [1.0, 0.4 * k, 0.15]) for k in range(4)]
>>> scene = Scene(boxes, np.zeros((0, 3)), ["b0", "b1", "b2", "b3"], np.zeros((4, 4)))
>>> examples = scene_examples(scene, r=3, isets=2, seed=0)
>>> examples.features.shape, int(examples.labels.sum())
((12, 19), 0)
"""

from __future__ import annotations

import hashlib
import os
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from unstack.errors import UnstackError
from unstack.learning.features import FeatureSettings, feature_names, pair_features
from unstack.parameters import COUNT, DETECTOR_NOISE, ISET_SIZE, JOBS, validate_params
from unstack.scene import Scene, load_scene
from unstack.understanding.detector import detector_poses

__all__ = [
    "ISET_DRAWS",
    "SupportExamples",
    "dataset_examples",
    "dataset_fingerprint",
    "detected_positions",
    "sample_isets",
    "scene_examples",
]


@dataclass(frozen=True)
class SupportExamples:
    """Feature rows with their labels and where they came from.

    Attributes
    ----------
    features : numpy.ndarray, shape (m, 19), or (m, 36) with the extended feature set
    labels : numpy.ndarray, shape (m,)
        1 for SUPP(X, Y), 0 otherwise.
    configuration : numpy.ndarray, shape (m,)
        Index of the scene in the data set.
    iset : numpy.ndarray, shape (m,)
        Index of the ISet within its scene.
    pairs : list of (str, str)
        ``(X, Y)`` ids of each row.
    """

    features: np.ndarray
    labels: np.ndarray
    configuration: np.ndarray
    iset: np.ndarray
    pairs: list[tuple[str, str]]

    @staticmethod
    def concatenate(parts: Sequence[SupportExamples], width: int = 19) -> SupportExamples:
        """Stack several sets of examples (those of no rows left out: a pile of one detected box
        gives none); ``width``: the features of the set of none."""
        parts = [part for part in parts if len(part.labels)]
        if not parts:
            return SupportExamples(np.zeros((0, width)), np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64),
                                   np.zeros(0, dtype=np.int64), [])  # fmt: skip
        return SupportExamples(
            np.concatenate([part.features for part in parts]),
            np.concatenate([part.labels for part in parts]),
            np.concatenate([part.configuration for part in parts]),
            np.concatenate([part.iset for part in parts]),
            [pair for part in parts for pair in part.pairs],
        )


#: How ISets are drawn: ``random`` boxes of the detected ones, or ``neighbours`` -- a random
#: detected box and its nearest detected boxes (centroid distance), as a detector sees a
#: patch of the pile. ``unstack experiment fig5a paper-test --isets-from neighbours --isets 2``
#: (paper-test: ``unstack simulate --configs 100 --seed 1``) draws 1,007 SUPP among 4,000
#: relations (25 %); random ISets of the training piles hold 8.9 % (paper: 33 %). ``mixed``
#: draws each ISet one way or the other at random.
ISET_DRAWS = ("random", "neighbours", "mixed")


def sample_isets(
    detected: Sequence[str],
    *,
    r: int,
    isets: int,
    rng: np.random.Generator,
    draw: str = "random",
    positions: np.ndarray | None = None,
) -> list[list[str]]:
    """``isets`` strict subsets of ``detected`` with ``min(r, len - 1)`` boxes each.

    Parameters
    ----------
    detected : sequence of str
    r : int
        Boxes per ISet.
    isets : int
        Number of ISets.
    rng : numpy.random.Generator
    draw : {"random", "neighbours"}
        See :data:`ISET_DRAWS`.
    positions : numpy.ndarray, shape (len(detected), 3), optional
        Centroids of the detected boxes (needed by ``neighbours``).

    Examples
    --------
    >>> sample_isets(["a", "b", "c"], r=5, isets=1, rng=np.random.default_rng(0))[0].__len__()
    2
    >>> line = np.array([[0.0, 0, 0], [1, 0, 0], [2, 0, 0], [9, 0, 0]])
    >>> sample_isets(["a", "b", "c", "d"], r=2, isets=1, rng=np.random.default_rng(1), draw="neighbours",
    ...              positions=line)
    [['a', 'b']]
    """
    if draw not in ISET_DRAWS:
        raise UnstackError(f"unknown ISet draw {draw!r}; expected one of {', '.join(ISET_DRAWS)}")
    size = min(r, len(detected) - 1)
    if size < 2:
        return []
    if draw == "random":
        return [sorted(rng.choice(list(detected), size=size, replace=False).tolist()) for _ in range(isets)]
    if positions is None or len(positions) != len(detected):
        raise UnstackError("neighbour ISets need the centroid of every detected box")
    result = []
    for _ in range(isets):
        if draw == "mixed" and rng.random() < 0.5:
            result.append(sorted(rng.choice(list(detected), size=size, replace=False).tolist()))
            continue
        centre = int(rng.integers(len(detected)))
        distances = np.linalg.norm(positions - positions[centre], axis=1)
        nearest = np.argsort(distances, kind="stable")[:size]
        result.append(sorted(detected[k] for k in nearest))
    return result


def detected_positions(scene: Scene) -> np.ndarray:
    """Centroids of the scene's detected boxes, in ``scene.detected`` order."""
    index = {box_id: k for k, box_id in enumerate(scene.box_ids)}
    return np.array([scene.boxes[index[box_id]].position for box_id in scene.detected], dtype=np.float64)


#: The arguments of :func:`scene_examples` and :func:`dataset_examples` checked at every call.
EXAMPLE_ARGUMENTS = {"r": ISET_SIZE, "isets": COUNT, "pose_noise": DETECTOR_NOISE}


@validate_params(EXAMPLE_ARGUMENTS)
def scene_examples(
    scene: Scene,
    *,
    r: int = 5,
    isets: int = 1,
    seed: int | np.random.SeedSequence = 0,
    settings: FeatureSettings | None = None,
    configuration: int = 0,
    draw: str = "random",
    vary_clouds: bool = False,
    pose_noise: float = 0.0,
) -> SupportExamples:
    """Examples of one scene with ground truth (``draw``: see :data:`ISET_DRAWS`).

    With ``vary_clouds`` each ISet sees the cloud as another sensor might
    (:func:`unstack.understanding.clouds.vary_cloud`: sparser, noisier, with holes). With ``pose_noise``
    (metres) each ISet's boxes are seen as a box detector reports them
    (:func:`detector_poses`): a simulated pile's boxes interpenetrate by fractions of a
    millimetre, a detector's are a centimetre off either way.
    """
    if scene.ground_truth is None:
        raise UnstackError(f"{scene.source}: $.ground_truth: training needs scenes with a ground-truth support matrix")
    rng = np.random.default_rng(seed)
    index = {box_id: k for k, box_id in enumerate(scene.box_ids)}
    parts = []
    drawn = sample_isets(scene.detected, r=r, isets=isets, rng=rng, draw=draw, positions=detected_positions(scene))
    for iset_index, iset in enumerate(drawn):
        pairs = [(index[x], index[y]) for x in iset for y in iset if x != y]
        points = scene.points
        if vary_clouds:
            from unstack.understanding.clouds import vary_cloud

            points = vary_cloud(points, rng)
        boxes = detector_poses(scene.boxes, pose_noise, rng) if pose_noise > 0 else scene.boxes
        features = pair_features(boxes, points, pairs, settings)
        labels = np.array([scene.ground_truth[x, y] for x, y in pairs], dtype=np.int64)
        parts.append(
            SupportExamples(
                features,
                labels,
                np.full(len(pairs), configuration, dtype=np.int64),
                np.full(len(pairs), iset_index, dtype=np.int64),
                [(scene.box_ids[x], scene.box_ids[y]) for x, y in pairs],
            )
        )
    return SupportExamples.concatenate(parts)


def _one_file(
    path: Path,
    r: int,
    isets: int,
    seed: int,
    settings: FeatureSettings,
    configuration: int,
    draw: str,
    vary_clouds: bool,
    pose_noise: float,
) -> SupportExamples:
    scene = load_scene(path)
    if len(scene.points) == 0:
        warnings.warn(f"{path}: the point cloud is empty; its DBAF features are 0", stacklevel=2)
    child = np.random.SeedSequence(seed, spawn_key=(configuration,))
    return scene_examples(
        scene,
        r=r,
        isets=isets,
        seed=child,
        settings=settings,
        configuration=configuration,
        draw=draw,
        vary_clouds=vary_clouds,
        pose_noise=pose_noise,
    )


def dataset_fingerprint(folder: str | os.PathLike[str]) -> str:
    """SHA-256 of a data set's manifest and scene files with their clouds (what a model was trained on)."""
    from unstack.dataset_folders import MANIFEST, dataset_digest, list_configurations

    digest = hashlib.sha256()
    manifest = Path(folder) / MANIFEST
    if manifest.is_file():
        digest.update(manifest.read_bytes())
    digest.update(dataset_digest(list_configurations(folder)).encode())
    return digest.hexdigest()


@validate_params({**EXAMPLE_ARGUMENTS, "n_jobs": JOBS})
def dataset_examples(
    folder: str | os.PathLike[str],
    *,
    r: int = 5,
    isets: int = 1,
    seed: int = 0,
    settings: FeatureSettings | None = None,
    n_jobs: int = 1,
    progress: Callable[[int, int], None] | None = None,
    draw: str = "random",
    vary_clouds: bool = False,
    pose_noise: float = 0.0,
) -> SupportExamples:
    """Examples of every scene of a simulated data set folder (``config-NNNN.json``).

    ``draw``: how ISets are drawn (see :data:`ISET_DRAWS`); ``vary_clouds`` and
    ``pose_noise``: see :func:`scene_examples`.

    ISets are seeded per configuration, so the examples do not depend on ``n_jobs``.
    """
    from joblib import Parallel, delayed

    from unstack.dataset_folders import require_configurations

    files = require_configurations(folder)
    settings = settings or FeatureSettings()
    if draw not in ISET_DRAWS:
        raise UnstackError(f"unknown ISet draw {draw!r}; expected one of {', '.join(ISET_DRAWS)}")
    tasks = (
        delayed(_one_file)(path, r, isets, seed, settings, int(path.stem.split("-")[1]), draw, vary_clouds, pose_noise)
        for path in files
    )
    parts: list[SupportExamples] = []
    for part in Parallel(n_jobs=n_jobs, return_as="generator")(tasks):
        parts.append(part)
        if progress is not None:
            progress(len(parts), len(files))
    examples = SupportExamples.concatenate(parts, width=len(feature_names(settings)))
    _warn_smaller_isets(examples, r, folder, len(files))
    drawn, repeated = repeated_isets(examples)
    if repeated > REPEATED_ISETS * drawn:
        warnings.warn(
            f"{folder}: {repeated:,} of the {drawn:,} ISets drawn repeat an earlier one of their pile (n detected "
            "boxes have only C(n, k) distinct sets of k): their relations are the same rows again, and a model "
            "trained on a split by pairs is scored on rows it was trained on; ask for fewer ISets (--isets), and "
            "train with a split by configuration",
            stacklevel=2,
        )
    return examples


def iset_boxes(examples: SupportExamples) -> dict[tuple[int, int], set[str]]:
    """The boxes of each ISet of the examples, by ``(configuration, iset)``.

    Examples
    --------
    >>> rows = SupportExamples(np.zeros((2, 1)), np.zeros(2, int), np.zeros(2, int), np.zeros(2, int),
    ...                        [("a", "b"), ("b", "a")])
    >>> {key: sorted(members) for key, members in iset_boxes(rows).items()}
    {(0, 0): ['a', 'b']}
    """
    boxes: dict[tuple[int, int], set[str]] = {}
    for configuration, iset, pair in zip(
        examples.configuration.tolist(), examples.iset.tolist(), examples.pairs, strict=True
    ):
        boxes.setdefault((configuration, iset), set()).update(pair)
    return boxes


def _warn_smaller_isets(examples: SupportExamples, r: int, folder: str | os.PathLike[str], piles: int) -> None:
    """Warn when piles too small for ISets of ``r`` boxes gave smaller ones (one box fewer than the
    pile's detected boxes, as the paper draws them), so that a larger ``r`` changes nothing there."""
    smaller = {(configuration, len(members)) for (configuration, _), members in iset_boxes(examples).items()
               if len(members) < r}  # fmt: skip
    if smaller:
        sizes = sorted({size for _, size in smaller})
        held = f"{sizes[0]}" if len(sizes) == 1 else f"{sizes[0]}-{sizes[-1]}"
        warnings.warn(
            f"{folder}: r = {r} is more than {len({pile for pile, _ in smaller})} of the {piles} piles can give: "
            f"their ISets hold {held} boxes (one fewer than the pile's detected boxes)",
            stacklevel=3,
        )


#: A share of ISets repeating one of their pile above which drawing them is warned about.
REPEATED_ISETS = 0.1


def repeated_isets(examples: SupportExamples) -> tuple[int, int]:
    """How many ISets the examples hold, and how many of them repeat an earlier ISet (the same
    boxes) of the same pile.

    Examples
    --------
    >>> rows = SupportExamples(np.zeros((6, 1)), np.zeros(6, int), np.zeros(6, int), np.array([0, 0, 1, 1, 2, 2]),
    ...                        [("a", "b"), ("b", "a"), ("b", "a"), ("a", "b"), ("a", "c"), ("c", "a")])
    >>> repeated_isets(rows)
    (3, 1)
    """
    boxes = iset_boxes(examples)
    seen = {(configuration, frozenset(members)) for (configuration, _), members in boxes.items()}
    return len(boxes), len(boxes) - len(seen)
