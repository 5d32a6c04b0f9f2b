"""``unstack train``, ``evaluate``, ``probabilities`` and ``decide`` on scene files."""

from __future__ import annotations

import json
import math
import shutil
from pathlib import Path

import jsonschema
import numpy as np
import pytest

from tests.conftest import REPO, assert_one_line_error, unstack
from unstack.dataset_folders import list_configurations
from unstack.jsonio import load_schema

pytestmark = pytest.mark.slow  # trains and evaluates models in subprocesses

SCENE = "examples/pile5.scene.json"


@pytest.fixture(scope="module")
def model(small_dataset: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    target = tmp_path_factory.mktemp("model") / "model.skops"
    result = unstack("train", str(small_dataset), "-o", str(target), "--r", "4", "--cv", "3", "--seed", "1")
    assert result.returncode == 0, result.stderr
    assert "chosen: C = " in result.stdout and "gamma = " in result.stdout
    assert "hold-out confusion matrix (Fig. 5 layout)" in result.stdout
    return target


def test_train_json_report_holds_hold_out_figures_of_a_model_fitted_on_all_rows(
    small_dataset: Path, tmp_path: Path
) -> None:
    result = unstack("train", str(small_dataset), "-o", str(tmp_path / "m.skops"), "--r", "4", "--cv", "3",
                     "--learner", "gradient_boosting", "--features", "extended", "--json")  # fmt: skip
    assert result.returncode == 0, result.stderr
    report = json.loads(result.stdout)
    assert report["learner"] == "gradient_boosting" and report["features"]["feature_set"] == "extended"
    assert report["training"]["r"] == 4
    assert report["validation"]["relations"] == math.ceil(0.3 * report["training"]["relations"])
    assert report["training"]["fitted_on"] == "all" and report["training"]["validation_size"] == 0.3
    assert len(report["training"]["fingerprint"]) == 64
    decided = unstack("decide", SCENE, "--model", str(tmp_path / "m.skops"), "--json")  # the model's features
    assert decided.returncode == 0, decided.stderr
    assert json.loads(decided.stdout)["objects"] == ["b03", "b04", "b06", "b13", "b14"]


def test_evaluate_prints_the_confusion_matrix_and_a_reliability_diagram(
    model: Path, small_dataset: Path, tmp_path: Path
) -> None:
    result = unstack("evaluate", str(model), str(small_dataset), "--r", "4", "--reliability", str(tmp_path / "r.png"))
    assert result.returncode == 0, result.stderr
    assert "balanced error rate (Eq. 16)" in result.stdout and "average entropy (Eq. 15)" in result.stdout
    assert (tmp_path / "r.png").read_bytes()[:4] == b"\x89PNG"
    assert "at the paper's SUPP recall (78.4 %) the best not-SUPP recall is" in result.stdout
    assert "relations with a feature outside the model's training range: " in result.stdout
    assert "out of distribution" not in result.stderr  # the model's own data
    report = json.loads(unstack("evaluate", str(model), str(small_dataset), "--r", "4", "--json").stdout)
    assert 0 <= report["out_of_range"]["share"] <= 0.1
    assert report["relations"] == report["supp"] + report["not_supp"]
    assert 0.0 <= report["fig5a"]["not_supp_recall"] <= 1.0 and report["fig5a"]["paper_not_supp_recall"] == 0.875


def test_probabilities_of_a_scene(model: Path, small_dataset: Path, tmp_path: Path) -> None:
    scene = list_configurations(small_dataset)[0]
    result = unstack("probabilities", str(scene), "--model", str(model), "-o", str(tmp_path / "p.json"))
    assert result.returncode == 0, result.stderr
    document = json.loads((tmp_path / "p.json").read_text())
    jsonschema.validate(document, load_schema("unstack.supports/1"))
    matrix = np.array(document["probabilities"])
    assert matrix.shape == (len(document["objects"]),) * 2 and np.all(np.diag(matrix) == 0)
    off_diagonal = matrix[~np.eye(len(matrix), dtype=bool)]
    assert np.all((off_diagonal > 0) & (off_diagonal < 1))  # learned values are never hard evidence


def test_decide_on_the_bundled_scene_with_the_default_model() -> None:
    result = unstack("decide", SCENE, "--json")
    assert result.returncode == 0, result.stderr
    decision = json.loads(result.stdout)
    jsonschema.validate(decision, load_schema("unstack.decision/1"))
    assert decision["objects"] == ["b03", "b04", "b06", "b13", "b14"]


def test_the_shipped_extended_model_by_name(tmp_path: Path) -> None:
    result = unstack("probabilities", SCENE, "--model", "extended", "-o", str(tmp_path / "p.json"))
    assert result.returncode == 0, result.stderr
    metadata = json.loads((tmp_path / "p.json").read_text())["metadata"]
    assert metadata["model"] == "shipped:extended-paper2.skops" and metadata["features"]["feature_set"] == "extended"
    decided = unstack("decide", SCENE, "--model", "extended", "--json")
    assert decided.returncode == 0, decided.stderr
    assert json.loads(decided.stdout)["objects"] == ["b03", "b04", "b06", "b13", "b14"]


def test_decide_on_a_scene_with_a_given_model(model: Path) -> None:
    result = unstack("decide", SCENE, "--model", str(model))
    assert result.returncode == 0, result.stderr
    assert "Unload first:" in result.stdout


@pytest.mark.parametrize(
    ("arguments", "message"),
    [
        (
            ["decide", SCENE, "--model", "examples/stack5.supports.json"],
            "expected an unstack model file (a skops file), got something else",
        ),
        (["decide", SCENE, "--model", "examples"], "examples: $: expected a model file, got a directory"),
        (["probabilities", SCENE, "--model", "nope.skops"], "nope.skops: $: cannot read the model file"),
        (
            ["train", "examples", "-o", "{tmp}/m.skops"],
            "examples: expected a data set folder with config-NNNN.json scene files",
        ),
        (
            ["train", "examples", "-o", "{tmp}/m.skops", "--r", "1"],
            "Invalid value for '--r': 1 is not in the range x>=2",
        ),
        (["evaluate", "nope.skops", "examples"], "nope.skops: $: cannot read the model file"),
        (["train", "{data}", "-o", "{tmp}/m.json"], "-o: expected a model file name ending in .skops, got"),
        (["train", "{data}", "{data}/", "-o", "{tmp}/m.skops"], "the data set is given twice"),
        (["train", "{data}", "-o", "{tmp}/m.skops", "--cv", "1"], "--cv: expected 2 to 1,000 cross-validation folds"),
        (["train", "{data}", "-o", "{tmp}/m.skops", "--cv", "99999999999999999999"], "got 99999999999999999999"),
    ],
)
def test_bad_input_is_one_line(arguments: list[str], message: str, tmp_path: Path, small_dataset: Path) -> None:
    result = unstack(*[argument.format(tmp=tmp_path, data=small_dataset) for argument in arguments])
    assert_one_line_error(result, message, nothing_written_in=tmp_path)


def test_an_empty_point_cloud_is_a_one_line_warning(tmp_path: Path) -> None:
    document = json.loads((REPO / "examples" / "scene3.json").read_text())
    document.pop("points_file", None)
    document["points"] = []
    scene = tmp_path / "empty.json"
    scene.write_text(json.dumps(document))
    result = unstack("probabilities", str(scene), "--no-statics")  # statics has its say on scene3 too
    assert result.returncode == 0, result.stderr
    assert result.stderr == (
        f"unstack: warning: {scene}: the point cloud is empty; undetected load and cloud features cannot be seen\n"
    )
    assert json.loads(result.stdout)["format"] == "unstack.supports/1"


LEANING = "examples/leaning.scene.json"


def test_a_box_leant_on_gets_its_support_from_statics_with_a_warning() -> None:
    result = unstack("decide", LEANING, "--json")
    assert result.returncode == 0, result.stderr
    decision = json.loads(result.stdout)
    costs = dict(zip(decision["objects"], decision["expected_costs"], strict=True))
    assert costs["upright"] > 0.6 > 0.5 > max(costs["free"], costs["lean"])  # statics price the box leant on
    assert decision["choice"] == "lean" and decision["ties"] == ["free", "lean"]  # the higher box holding nothing up
    assert "without 'upright' (its centre of mass lies" in result.stderr
    assert any("P(upright supports lean) raised from" in warning for warning in decision["warnings"])


def test_no_statics_keeps_the_models_probabilities(tmp_path: Path) -> None:
    with_statics = unstack("probabilities", LEANING, "-o", str(tmp_path / "with.json"))
    without = unstack("probabilities", LEANING, "--no-statics", "-o", str(tmp_path / "without.json"))
    assert with_statics.returncode == without.returncode == 0, without.stderr
    raised = json.loads((tmp_path / "with.json").read_text())
    kept = json.loads((tmp_path / "without.json").read_text())
    upright, lean = (raised["objects"].index(name) for name in ("upright", "lean"))
    assert raised["probabilities"][upright][lean] == 0.65 > kept["probabilities"][upright][lean]
    assert raised["metadata"]["tip_supports"][0]["supporter"] == "upright" and kept["metadata"]["tip_supports"] == []
    assert without.stderr == ""


def test_no_statics_on_a_supports_file_is_one_line() -> None:
    result = unstack("decide", "examples/stack5.supports.json", "--no-statics")
    assert_one_line_error(result, "--no-statics applies to a scene file")


def test_a_model_is_not_written_over_a_file_of_its_data_set(small_dataset: Path, tmp_path: Path) -> None:
    data = tmp_path / "data"
    shutil.copytree(small_dataset, data)
    scene = sorted(data.glob("config-*.json"))[0]
    target = scene.with_suffix(".skops")
    target.write_bytes(scene.read_bytes())  # a data set file under a model's name
    before = target.read_bytes()
    result = unstack("train", str(data), "-o", str(target))
    assert_one_line_error(result, f"{target}: cannot write there: it is the input file")
    assert target.read_bytes() == before


@pytest.mark.slow  # a subprocess
def test_train_does_not_write_over_the_shipped_models(small_dataset: Path) -> None:
    """Every later decide would have used it: `train -o <package>/learning/models/general-mix.skops`."""
    from unstack.learning.model_file import default_model_path

    shipped = default_model_path()
    before = shipped.read_bytes()
    result = unstack("train", str(small_dataset), "-o", str(shipped), "--cv", "3")
    assert_one_line_error(result, "cannot write there: the folder of the models shipped with unstack")
    assert shipped.read_bytes() == before
