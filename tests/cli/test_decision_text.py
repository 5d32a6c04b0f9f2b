"""The decision's terminal text explains itself: the pick's place, the cost in words, the model, no "None"."""

from __future__ import annotations

import io
import json
from pathlib import Path

import jsonschema
import numpy as np
import pytest
from rich.console import Console

import unstack
from tests.conftest import EXAMPLES, PILE5
from tests.conftest import unstack as unstack_cli
from unstack.cli.render import decision_view, plan_view
from unstack.jsonio import load_schema
from unstack.supports import Supports


def text_of(decision: unstack.Decision) -> str:
    buffer = io.StringIO()
    Console(file=buffer, width=400, highlight=False).print(decision_view(decision))
    return buffer.getvalue()


@pytest.fixture(scope="module")
def scene_decision() -> unstack.Decision:
    return unstack.decide(unstack.load(EXAMPLES / "pile5.scene.json"))


@pytest.mark.slow  # loads the default model
def test_a_scene_decision_names_its_model_cost_and_where_the_pick_is(scene_decision: unstack.Decision) -> None:
    text = text_of(scene_decision)
    assert "support model: general (the default model)" in text
    assert "EC, the expected cost 'load': the boxes that would come down with it" in text and "lower is safer" in text
    assert "the undetected load the point cloud shows on them" in text
    assert "where: x " in text and "(centre), top at" in text and "top of 5 detected" in text
    assert "EC (boxes brought down)" in text and "None" not in text


@pytest.mark.slow  # loads the default model
def test_the_pick_is_where_the_scene_has_it(scene_decision: unstack.Decision) -> None:
    from unstack.geometry import bounding_boxes

    scene = unstack.load(EXAMPLES / "pile5.scene.json")
    tops = {
        box: float(bounds[5])
        for box, bounds in zip(scene.detected, bounding_boxes([scene.box(b) for b in scene.detected]), strict=True)
    }
    pick = scene_decision.pick
    assert pick is not None and pick["top"] == pytest.approx(tops[scene_decision.choice], abs=1e-4)
    assert pick["height_rank"] == 1 + sum(top > tops[scene_decision.choice] for top in tops.values())
    assert pick["centre"] == pytest.approx(scene.box(scene_decision.choice).position.tolist(), abs=1e-4)


@pytest.mark.slow  # loads the default model
def test_the_json_carries_the_model_and_the_pick_and_validates(scene_decision: unstack.Decision) -> None:
    document = json.loads(json.dumps(scene_decision.to_dict()))
    jsonschema.validate(document, load_schema("unstack.decision/1"))
    assert document["model"] == "default:general-mix.skops" and document["pick"]["boxes"] == 5


@pytest.mark.parametrize("seed", [None, 3])
def test_a_sampled_decision_says_its_seed_in_words(seed: int | None) -> None:
    supports = Supports([f"b{k}" for k in range(3)], [[0, 0.4, 0.2], [0.3, 0, 0.6], [0.5, 0.1, 0]])
    decision = unstack.decide(supports, method="approx", samples=64, seed=seed)
    text = text_of(decision)
    assert "None" not in text and "support model: none (the probabilities were given)" in text
    assert ("seed 3" in text) if seed is not None else ("no seed" in text and "--seed 0 repeats one" in text)
    assert decision.sampling is not None and f"--samples {4 * max(decision.sampling['samples'])} halves them" in text


def test_supports_with_heights_say_where_the_pick_rests() -> None:
    supports = Supports(["low", "high"], [[0, 0.9], [0.05, 0]], heights=[0.0, 0.4])
    decision = unstack.decide(supports)
    assert decision.pick == {"rests_at": 0.4, "height_rank": 1, "boxes": 2}
    assert "where: resting at 0.40 m: the highest of 2" in text_of(decision)


def test_supports_without_heights_have_no_place() -> None:
    decision = unstack.decide(Supports(["a", "b"], [[0, 0.2], [0.7, 0]]))
    assert decision.pick is None and "where:" not in text_of(decision) and "pick" not in decision.to_dict()


def test_hard_evidence_is_counted_in_words() -> None:
    decision = unstack.decide(Supports(["a", "b", "c"], [[0, 1.0, 0.2], [0.0, 0, 0.3], [0.1, 0.2, 0]]))
    assert "hard evidence (probabilities 0 or 1): 1 forced, 1 forbidden" in text_of(decision)


@pytest.mark.slow  # subprocesses on an empty numba cache compile the contact kernel
def test_a_first_call_that_compiles_says_so_and_the_next_one_is_quiet(tmp_path: Path) -> None:
    call = ("decide", "examples/pile5.scene.json", "--model", "extended")
    first = unstack_cli(*call, env={"NUMBA_CACHE_DIR": str(tmp_path)})
    assert first.returncode == 0, first.stderr
    assert "unstack: note: numba is compiling the feature kernels for first use in this environment" in first.stderr
    assert "'unstack warm-up' compiles every kernel at once" in first.stderr
    again = unstack_cli(*call, env={"NUMBA_CACHE_DIR": str(tmp_path)})
    assert again.returncode == 0 and "numba is compiling" not in again.stderr


@pytest.mark.slow  # a subprocess
def test_a_call_in_plain_python_says_nothing(tmp_path: Path) -> None:
    result = unstack_cli("decide", PILE5, env={"NUMBA_CACHE_DIR": str(tmp_path)})
    assert result.returncode == 0 and result.stderr == ""


def plan_text(result: unstack.Plan) -> str:
    buffer = io.StringIO()
    Console(file=buffer, width=400, highlight=False).print(plan_view(result))
    return buffer.getvalue()


def test_an_exact_plan_says_what_its_ec_column_counts() -> None:
    text = plan_text(unstack.plan(Supports(["top", "bottom"], [[0.0, 0.1], [0.9, 0.0]])))
    assert "EC: the expected cost of the pick among the boxes in place, cost 'load'" in text
    assert "± s.e." not in text and "P(minimum)" not in text


def test_a_sampled_plan_says_what_its_error_and_probability_columns_mean() -> None:
    rng = np.random.default_rng(3)
    probabilities = rng.uniform(0.0, 1.0, (12, 12)) * (rng.uniform(size=(12, 12)) < 0.3)
    np.fill_diagonal(probabilities, 0.0)
    result = unstack.plan(Supports([f"b{i}" for i in range(12)], probabilities), method="approx", samples=200, seed=0)
    text = plan_text(result)
    assert "± s.e.: its standard error" in text
    assert "P(minimum): the probability that the pick truly has the lowest EC at its step (the sampler" in text


def test_expected_costs_too_small_for_four_decimals_keep_three_significant_digits() -> None:
    grams = Supports(["top", "bottom"], [[0.0, 0.1], [0.9, 0.0]], masses=[2e-6, 3e-6])
    text = text_of(unstack.decide(grams, cost="mass"))
    assert "3e-07" in text and "1.8e-06" in text and "0.0000" not in text
    assert "0.1000" in text_of(unstack.decide(grams, cost="count"))


@pytest.mark.slow  # the physics engine is imported
def test_a_physics_veto_not_applied_says_so_and_keeps_the_pick() -> None:
    boxes = [
        unstack.Box("low", [0.4, 0.4, 0.3], [1.0, -0.1, 0.15]),
        unstack.Box("high", [0.4, 0.4, 0.3], [1.0, 0.3, 0.75]),
    ]
    decision = unstack.decide(unstack.Scene(boxes, np.zeros((0, 3)), ["low", "high"]), seed=0, physics_veto=True)
    assert (
        "physics on what the robot sees: not applied, 1 pose cannot stand as reported (see the warning); the "
        f"reasoner's pick {decision.choice} is kept" in text_of(decision)
    )


@pytest.mark.parametrize("encoding", ["ascii", "latin-1"])
def test_ids_an_ascii_terminal_cannot_show_are_escaped_not_a_crash(tmp_path: Path, encoding: str) -> None:
    supports = Supports(["é1", "箱", "b"], [[0, 0.6, 0.1], [0.1, 0, 0.5], [0.2, 0.1, 0]])
    supports.save(tmp_path / "odd.json")
    import os
    import subprocess
    import sys

    result = subprocess.run(
        [sys.executable, "-m", "unstack", "decide", str(tmp_path / "odd.json")],
        capture_output=True, timeout=300, env={**os.environ, "PYTHONIOENCODING": encoding},
    )  # fmt: skip
    assert result.returncode == 0, result.stderr
    assert b"\\u7bb1" in result.stdout and b"Traceback" not in result.stderr


@pytest.mark.parametrize("columns", ["0", "20", "abc"])
def test_a_terminal_too_narrow_for_the_tables_still_gets_the_pick(columns: str) -> None:
    result = unstack_cli("decide", str(EXAMPLES / "stack5.supports.json"), env={"COLUMNS": columns})
    assert result.returncode == 0 and result.stdout.startswith("Unload first: top_left")
    assert "top_right" in result.stdout  # the ranking's cells hold ids, not only "…"
