"""Training examples: ISets are strict subsets, labels come from the ground truth, seeds are per scene."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from unstack.dataset_folders import list_configurations
from unstack.errors import UnstackError
from unstack.learning.training_data import dataset_examples, dataset_fingerprint, sample_isets, scene_examples
from unstack.scene import load_scene


@pytest.mark.parametrize(("detected", "r", "size"), [(10, 5, 5), (5, 5, 4), (3, 5, 2), (2, 5, 0)])
def test_isets_are_strict_subsets(detected: int, r: int, size: int, rng: np.random.Generator) -> None:
    ids = [f"b{k}" for k in range(detected)]
    isets = sample_isets(ids, r=r, isets=4, rng=rng)
    assert all(len(iset) == size and len(set(iset)) == size and set(iset) < set(ids) for iset in isets)
    assert len(isets) == (4 if size else 0)


@pytest.mark.slow  # simulates the small data set
def test_labels_are_the_ground_truth(small_dataset: Path) -> None:
    scene = load_scene(list_configurations(small_dataset)[0])
    examples = scene_examples(scene, r=4, isets=3, seed=1)
    index = {box_id: k for k, box_id in enumerate(scene.box_ids)}
    truth = scene.ground_truth
    assert truth is not None
    assert examples.labels.tolist() == [int(truth[index[x], index[y]]) for x, y in examples.pairs]
    assert examples.features.shape == (3 * 4 * 3, 19)


@pytest.mark.slow  # simulates the small data set
def test_examples_do_not_depend_on_the_number_of_processes(small_dataset: Path) -> None:
    one = dataset_examples(small_dataset, r=4, isets=2, seed=3, n_jobs=1)
    two = dataset_examples(small_dataset, r=4, isets=2, seed=3, n_jobs=2)
    assert np.array_equal(one.features, two.features) and one.pairs == two.pairs
    assert sorted(set(one.configuration.tolist())) == list(range(len(list_configurations(small_dataset))))


@pytest.mark.slow  # simulates the small data set
def test_fingerprint_changes_with_the_data(small_dataset: Path, tmp_path: Path) -> None:
    assert dataset_fingerprint(small_dataset) == dataset_fingerprint(small_dataset)
    assert dataset_fingerprint(small_dataset) != dataset_fingerprint(tmp_path)


def test_fingerprint_changes_with_a_cloud(tmp_path: Path, examples: Path) -> None:
    """The fingerprint hashed the scene JSONs alone: a model trained on other clouds told the same data."""
    import json
    import shutil

    scene = json.loads((examples / "scene3.json").read_text())
    shutil.copy(examples / scene["points_file"], tmp_path / scene["points_file"])
    (tmp_path / "config-0000.json").write_text(json.dumps(scene))
    before = dataset_fingerprint(tmp_path)
    cloud = np.load(tmp_path / scene["points_file"])
    np.save(tmp_path / scene["points_file"], cloud + np.array([0.0, 0.0, 0.5]))
    assert dataset_fingerprint(tmp_path) != before


def test_a_folder_without_scenes(tmp_path: Path) -> None:
    with pytest.raises(UnstackError, match=r"expected a data set folder with config-NNNN\.json scene files"):
        dataset_examples(tmp_path)


def test_neighbour_isets_are_the_nearest_boxes_to_a_centre(rng: np.random.Generator) -> None:
    positions = rng.uniform(0.0, 3.0, (12, 3))
    ids = [f"b{k:02d}" for k in range(12)]
    for iset in sample_isets(ids, r=4, isets=20, rng=rng, draw="neighbours", positions=positions):
        members = [ids.index(box) for box in iset]
        # some member is the centre: the other members are its 3 nearest boxes
        assert any(
            set(np.argsort(np.linalg.norm(positions - positions[c], axis=1), kind="stable")[:4]) == set(members)
            for c in members
        )


@pytest.mark.slow  # simulates the small data set
@pytest.mark.filterwarnings("ignore:.*ISets drawn repeat")  # nearest neighbours of few boxes repeat, as they should
def test_neighbour_isets_hold_more_support_relations(small_dataset: Path) -> None:
    near = dataset_examples(small_dataset, r=4, isets=6, seed=0, draw="neighbours")
    assert near.features.shape[1] == 19 and len(near.labels) > 0
    assert near.labels.mean() >= dataset_examples(small_dataset, r=4, isets=6, seed=0).labels.mean()


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [({"draw": "clusters"}, "unknown ISet draw 'clusters'"), ({"draw": "neighbours"}, "need the centroid")],
)
def test_bad_iset_draws(kwargs: dict[str, str], message: str, rng: np.random.Generator) -> None:
    with pytest.raises(UnstackError, match=message):
        sample_isets(["a", "b", "c"], r=2, isets=1, rng=rng, **kwargs)


def test_more_isets_than_a_pile_has_distinct_ones_are_warned_about(small_dataset: Path) -> None:
    with pytest.warns(
        UserWarning, match=r"of the 800 ISets drawn repeat an earlier one of their pile .* split by pairs"
    ):
        examples = dataset_examples(small_dataset, r=2, isets=100, seed=0)
    from unstack.learning.training_data import repeated_isets

    drawn, repeated = repeated_isets(examples)
    assert drawn == 800 and repeated > 80


def test_a_few_isets_of_a_large_pile_are_not_warned_about(small_dataset: Path) -> None:
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        dataset_examples(small_dataset, r=2, isets=1, seed=0)


def test_isets_larger_than_a_pile_can_give_are_warned_about_with_the_sizes_drawn(small_dataset: Path) -> None:
    with pytest.warns(UserWarning, match=r"r = 100 is more than 8 of the 8 piles can give: their ISets hold \d+(-\d+)? "
                      r"boxes \(one fewer than the pile's detected boxes\)"):  # fmt: skip
        dataset_examples(small_dataset, r=100, isets=1, seed=0)


@pytest.mark.parametrize("width", [15, 36])
def test_a_pile_that_gives_no_examples_stacks_with_the_features_of_any_set(width: int) -> None:
    """A pile of one detected box gives no ISet; its empty part was 19 columns wide whatever the set."""
    from unstack.learning.training_data import SupportExamples

    none = SupportExamples.concatenate([])
    some = SupportExamples(np.ones((2, width)), np.array([0, 1]), np.zeros(2, np.int64), np.zeros(2, np.int64),
                           [("a", "b"), ("b", "a")])  # fmt: skip
    assert SupportExamples.concatenate([none, some, none]).features.shape == (2, width)
    assert SupportExamples.concatenate([none], width=width).features.shape == (0, width)
