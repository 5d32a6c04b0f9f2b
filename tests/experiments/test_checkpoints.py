"""A pile's checkpoint is taken only when it is whole and of the same run; anything else is run again."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from unstack.experiments.outputs import stored_result

KEY = {"scene_sha256": "ab", "seed": 3}


@pytest.mark.parametrize(
    "text",
    ["null", "[]", '"x"', "5", '{"key": {"seed": 3}}', json.dumps({"key": KEY, "result": 5}), '{"key": ', ""],
)
def test_a_damaged_checkpoint_is_run_again(tmp_path: Path, text: str) -> None:
    (tmp_path / "pile.json").write_text(text)
    assert stored_result(tmp_path / "pile.json", KEY) is None


def test_a_checkpoint_of_another_run_is_run_again_and_the_same_run_is_taken(tmp_path: Path) -> None:
    (tmp_path / "pile.json").write_text(json.dumps({"key": KEY, "result": {"runs": {"highest": {}}}}))
    assert stored_result(tmp_path / "pile.json", {**KEY, "seed": 4}) is None
    assert stored_result(tmp_path / "pile.json", KEY) == {"runs": {"highest": {}}}


def test_results_are_written_as_strict_json_with_null_for_undefined_values(tmp_path: Path) -> None:
    from unstack.experiments.outputs import save_results
    from unstack.jsonio import read_document

    result = {"reliability": {"mean_predicted": [0.1, float("nan")]}, "spearman": float("nan"), "piles": 2}
    [written] = save_results(tmp_path, "result.json", result)
    text = written.read_text()
    assert "NaN" not in text and json.loads(text)["reliability"]["mean_predicted"] == [0.1, None]
    assert read_document(written).data["spearman"] is None  # unstack's own reader takes it


def test_a_pile_whose_cloud_changed_is_another_pile(tmp_path: Path, examples: Path) -> None:
    """The key hashed the scene's JSON alone: a changed points file reused the old result."""
    import shutil

    import numpy as np

    from unstack.dataset_folders import scene_digest

    scene = json.loads((examples / "scene3.json").read_text())
    shutil.copy(examples / scene["points_file"], tmp_path / scene["points_file"])
    (tmp_path / "scene.json").write_text(json.dumps(scene))
    before = scene_digest(tmp_path / "scene.json")
    cloud = np.load(tmp_path / scene["points_file"])
    np.save(tmp_path / scene["points_file"], cloud + np.array([0.0, 0.0, 0.5]))
    assert scene_digest(tmp_path / "scene.json") != before


def test_two_model_files_of_one_metadata_are_two_models(tmp_path: Path) -> None:
    """The key hashed the metadata alone: another estimator under the same metadata reused the results."""
    import shutil

    from unstack.experiments.outputs import model_digest
    from unstack.learning.model_file import default_model_path, load_model

    shutil.copy(default_model_path(), tmp_path / "a.skops")
    model = load_model(tmp_path / "a.skops")
    same = model_digest(model)
    assert model_digest(load_model(tmp_path / "a.skops")) == same
    (tmp_path / "b.skops").write_bytes((tmp_path / "a.skops").read_bytes() + b"\0")  # other bytes, one metadata
    other = type(model)(model.estimator, model.features, model.metadata, source=str(tmp_path / "b.skops"))
    assert model_digest(other) != same
