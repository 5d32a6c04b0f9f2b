"""The ``unstack`` commands, run as a user runs them (a subprocess per call)."""

from __future__ import annotations

import json
from pathlib import Path

import jsonschema
import numpy as np
import pytest

from tests.conftest import PILE5, assert_one_line_error, unstack
from unstack.jsonio import load_schema

pytestmark = pytest.mark.slow  # runs the CLI in subprocesses


def test_decide_prints_a_table() -> None:
    result = unstack("decide", PILE5)
    assert result.returncode == 0, result.stderr
    assert "Unload first: top_left" in result.stdout
    assert "P(row supports column | consistent world)" in result.stdout
    assert "6,942 consistent worlds" in result.stdout


def test_decide_json_follows_the_decision_schema() -> None:
    result = unstack("decide", PILE5, "--json")
    document = json.loads(result.stdout)
    jsonschema.validate(document, load_schema("unstack.decision/1"))
    assert document["choice"] == "top_left"
    assert document["consistent_worlds"] == 6942
    costs = np.array(document["expected_costs"])
    np.testing.assert_allclose(costs, np.array(document["marginals"]).sum(axis=1), atol=1e-12)


def test_decide_reads_stdin_and_writes_output_atomically(tmp_path: Path, repo: Path) -> None:
    output = tmp_path / "decision.json"
    text = (repo / PILE5).read_text()
    result = unstack("decide", "-", "--output", str(output), stdin=text)
    assert result.returncode == 0, result.stderr
    assert json.loads(output.read_text())["choice"] == "top_left"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["decision.json"]


@pytest.mark.parametrize("method", ["exact", "sat"])
def test_methods_give_the_same_choice(method: str) -> None:
    document = json.loads(unstack("decide", PILE5, "--json", "--method", method).stdout)
    assert document["method"] == method
    assert document["choice"] == "top_left"


def test_mass_cost() -> None:
    document = json.loads(unstack("decide", PILE5, "--json", "--cost", "mass").stdout)
    assert document["cost"] == "mass"
    assert max(document["expected_costs"]) > 10


def test_worlds_shows_table_ii() -> None:
    result = unstack("worlds", "examples/evidence3.supports.json")
    assert result.returncode == 0, result.stderr
    assert "Payoff matrix (Table II)" in result.stdout
    assert "2 consistent worlds" in result.stdout
    document = json.loads(unstack("worlds", "examples/evidence3.supports.json", "--json").stdout)
    assert document["consistent_worlds"] == 2
    assert sum(world["probability"] for world in document["worlds"]) == pytest.approx(1.0)


def test_worlds_refuses_large_scenes() -> None:
    result = unstack("worlds", "examples/pile7.supports.json")
    assert result.returncode == 2
    assert "limited to 6 boxes" in result.stderr


def test_validate_reports_each_file(tmp_path: Path, repo: Path) -> None:
    decision = tmp_path / "d.json"
    unstack("decide", PILE5, "-o", str(decision))
    result = unstack("validate", *sorted(str(p) for p in (repo / "examples").glob("*.json")), str(decision))
    assert result.returncode == 0, result.stderr
    assert "valid unstack.scene/1 (3 boxes, 3 detected, 900 points)" in result.stdout
    assert "valid unstack.decision/1" in result.stdout


BAD = [
    pytest.param("{oops", "invalid JSON at line 1 column 2", id="malformed"),
    pytest.param(
        '{"format": "unstack.supports/7", "objects": ["a"], "probabilities": [[0]]}',
        "unsupported version",
        id="version",
    ),
    pytest.param(
        '{"format": "unstack.supports/1", "objects": ["a", "b"], "probabilities": [[0, 1], [0.5]]}',
        r"$.probabilities[1]: expected 2 numbers",
        id="ragged",
    ),
    pytest.param(
        '{"format": "unstack.supports/1", "objects": ["a", "b", "c"], "probabilities": [[0, 1, 0], [0, 0, 1], [0.5, 0.5, 0]]}',
        "no consistent world: P(SUPP(a, b)) = 1 and P(SUPP(b, c)) = 1 force SUPP(a, c)",
        id="contradiction",
    ),
]


@pytest.mark.parametrize(("text", "message"), BAD)
@pytest.mark.parametrize("command", ["decide", "worlds"])
def test_bad_input_is_one_line_exit_2_and_no_output(tmp_path: Path, text: str, message: str, command: str) -> None:
    source = tmp_path / "bad.json"
    source.write_text(text)
    output = tmp_path / "out.json"
    result = unstack(command, str(source), "--output", str(output))
    assert result.returncode == 2
    assert result.stderr.count("\n") == 1, result.stderr
    assert result.stderr.startswith(f"unstack: error: {source}: ") or "no consistent world" in result.stderr
    assert message in result.stderr
    assert "Traceback" not in result.stderr
    assert not output.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.json"]


def test_a_scene_file_is_decided_through_the_shipped_model() -> None:
    result = unstack("decide", "examples/scene3.json", "--json")
    assert result.returncode == 0, result.stderr
    assert json.loads(result.stdout)["objects"] == ["top", "floor_a", "floor_b"]


def test_usage_errors_exit_2() -> None:
    result = unstack("decide", PILE5, "--method", "magic")
    assert result.returncode == 2
    assert "Invalid value for '--method'" in result.stderr


@pytest.fixture
def twelve_boxes(tmp_path: Path) -> Path:
    """A 12-box supports file: too many linked boxes to count, so auto samples."""
    rng = np.random.default_rng(12)
    p = rng.uniform(0.01, 0.08, (12, 12))
    for below in range(0, 9):
        p[below, below + 3] = 0.9  # columns of four boxes
    np.fill_diagonal(p, 0.0)
    document = {
        "format": "unstack.supports/1",
        "objects": [f"b{i:02d}" for i in range(12)],
        "probabilities": p.tolist(),
    }
    path = tmp_path / "twelve.supports.json"
    path.write_text(json.dumps(document))
    return path


def test_decide_samples_large_groups_reproducibly(twelve_boxes: Path) -> None:
    runs = [unstack("decide", str(twelve_boxes), "--json", "--samples", "800", "--seed", "3") for _ in range(2)]
    assert runs[0].stdout == runs[1].stdout  # canonical: byte for byte
    documents = [json.loads(run.stdout) for run in runs]
    for document in documents:
        jsonschema.validate(document, load_schema("unstack.decision/1"))
        assert "timing" not in document and "seconds" not in document
    assert documents[0]["method"] == "approx" and documents[0]["choice"] in {"b09", "b10", "b11"}
    assert all(error > 0 for error in documents[0]["expected_cost_errors"])
    table = unstack("decide", str(twelve_boxes), "--time-limit", "0.3")
    assert table.returncode == 0, table.stderr
    assert "± s.e." in table.stdout and "P(truly the minimum EC)" in table.stdout


def test_approx_method_on_a_small_scene_agrees_with_exact() -> None:
    document = json.loads(unstack("decide", PILE5, "--json", "--method", "approx", "--samples", "4000").stdout)
    exact = json.loads(unstack("decide", PILE5, "--json").stdout)
    assert document["choice"] == exact["choice"]
    errors = np.abs(np.array(document["expected_costs"]) - np.array(exact["expected_costs"]))
    assert np.all(errors <= 5 * np.array(document["expected_cost_errors"]) + 2e-3)


def test_plan_with_sampling(twelve_boxes: Path) -> None:
    result = unstack("plan", str(twelve_boxes), "--json", "--samples", "400", "--seed", "0")
    assert result.returncode == 0, result.stderr
    document = json.loads(result.stdout)
    jsonschema.validate(document, load_schema("unstack.plan/1"))
    assert document["steps"][0]["method"] == "approx" and document["steps"][-1]["method"] in {"exact", "sat"}
    assert document["steps"][0]["expected_cost_error"] > 0


def test_decide_on_a_scene_gives_near_ties_to_the_box_resting_highest(tmp_path: Path) -> None:
    from unstack.scene import Box, Scene

    boxes = [
        Box("low", [0.4, 0.4, 0.3], [1.2, -0.35, 0.151]),
        Box("base", [0.4, 0.4, 0.3], [1.2, 0.35, 0.151]),
        Box("high", [0.4, 0.4, 0.3], [1.2, 0.35, 0.452]),
    ]
    path = tmp_path / "three.scene.json"
    Scene(boxes, np.zeros((0, 3)), ["low", "base", "high"]).save(path)
    default = unstack("decide", str(path), "--json", "--free-cost", "0")  # the reasoner's own choice
    assert default.returncode == 0, default.stderr
    document = json.loads(default.stdout)
    assert document["choice"] == "high" and document["near_tie_margin"] == 0.05
    assert sorted(document["ties"]) == ["high", "low"]
    strict = json.loads(unstack("decide", str(path), "--json", "--near-ties", "0").stdout)
    assert "near_tie_margin" not in strict and strict["choice"] == min(
        strict["objects"], key=lambda box: (strict["expected_costs"][strict["objects"].index(box)], box)
    )
    table = unstack("decide", str(path), "--free-cost", "0")
    words = " ".join(table.stdout.split())  # rich wraps the headline
    assert (
        "Unload first: high (tied with low: EC within 0.05 of the lowest; the box resting highest wins, on one layer the lowest EC)"
        in words
    )


def test_decide_on_a_scene_takes_the_highest_free_box_unless_free_cost_is_0(tmp_path: Path) -> None:
    from unstack.scene import Box, Scene

    boxes = [  # 'tall' and 'low' hold nothing up; 'tall' is the higher, 'low' the slightly cheaper
        Box("tall", [0.4, 0.4, 0.8], [1.2, -0.35, 0.401]),
        Box("low", [0.4, 0.4, 0.3], [1.2, 0.35, 0.151]),
    ]
    path = tmp_path / "two.scene.json"
    Scene(boxes, np.zeros((0, 3)), ["tall", "low"]).save(path)
    default = json.loads(unstack("decide", str(path), "--json").stdout)
    assert (default["choice"], default["free_cost"]) == ("tall", 0.5)
    assert default["ties"] == ["low", "tall"]
    strict = json.loads(unstack("decide", str(path), "--json", "--free-cost", "0").stdout)
    assert "free_cost" not in strict and strict["choice"] == min(
        strict["objects"], key=lambda box: (strict["expected_costs"][strict["objects"].index(box)], box)
    )
    words = " ".join(unstack("decide", str(path)).stdout.split())
    assert (
        "Unload first: tall (tied with low: EC below 0.5, so more likely than not holding nothing up; the box whose centre is highest wins "
        "(on equal heights, the larger id))" in words
    )


def test_a_free_cost_on_support_probabilities_exits_2_naming_the_option() -> None:
    result = unstack("decide", PILE5, "--free-cost", "0.5")
    assert_one_line_error(result, "--free-cost takes the highest box by its centre")


def test_near_ties_on_supports_without_heights_exit_2() -> None:
    result = unstack("decide", PILE5, "--near-ties", "0.1")
    assert_one_line_error(result, "carry no heights", "stack5.supports.json")


def test_decide_says_why_for_the_pick_and_the_runner_up(tmp_path: Path) -> None:
    path = tmp_path / "two.supports.json"
    path.write_text(
        json.dumps(
            {"format": "unstack.supports/1", "objects": ["top", "bottom"], "probabilities": [[0, 0.1], [0.9, 0]]}
        )
    )
    result = unstack("decide", str(path))
    assert result.returncode == 0, result.stderr
    assert "pick top: EC 0.10 boxes brought down (top may hold up bottom: P 0.10; held up by bottom: P 0.90)" in (
        result.stdout.replace("\n", " ").replace("  ", " ")
    )
    assert "runner-up bottom: EC 0.90 boxes brought down (bottom holds up top: P 0.90)" in result.stdout
    assert "with the undetected load the supports file gives on them, hidden_load" in (
        result.stdout.replace("\n", " ").replace("  ", " ")
    )  # a supports file has no point cloud


def test_a_plan_says_up_front_that_its_time_limit_is_per_step() -> None:
    result = unstack("plan", PILE5, "--time-limit", "20", "--seed", "0", "--json")
    assert result.returncode == 0, result.stderr
    assert "unstack: note: --time-limit applies to each of the 5 steps: the plan may sample for 1.7 min in all" in (
        result.stderr.splitlines()
    )
