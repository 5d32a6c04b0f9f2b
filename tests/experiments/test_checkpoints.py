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
