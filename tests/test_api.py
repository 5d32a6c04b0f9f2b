"""The top-level API a planner codes against: unstack.load_model, support_probabilities, decide, plan."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import unstack
from unstack.errors import InvalidArgument, InvalidFile


@pytest.mark.slow
def test_a_scene_is_decided_through_the_default_model(examples: Path) -> None:
    scene = unstack.load(examples / "pile5.scene.json")
    assert isinstance(scene, unstack.Scene)
    decision = unstack.decide(scene)
    supports = unstack.support_probabilities(scene)
    assert decision.objects == supports.objects == scene.detected
    np.testing.assert_array_equal(decision.expected_costs, unstack.decide(supports).expected_costs)
    assert supports.metadata["model"].startswith("default:")


@pytest.mark.slow
def test_a_shipped_model_is_named_and_loaded_once(examples: Path) -> None:
    scene = unstack.load_scene(examples / "pile5.scene.json")
    extended = unstack.load_model("extended")
    assert unstack.load_model("extended") is extended
    by_name = unstack.decide(scene, model="extended")
    by_object = unstack.decide(scene, model=extended)
    np.testing.assert_array_equal(by_name.expected_costs, by_object.expected_costs)
    assert unstack.support_probabilities(scene, "extended").metadata["model"] == "shipped:extended-paper2.skops"


def test_a_model_file_is_loaded_by_path(tmp_path: Path) -> None:
    from unstack.learning.model_file import bundled_model_path

    copy = tmp_path / "paper"  # named like a shipped model: a path reaches the file
    copy.write_bytes(bundled_model_path("paper").read_bytes())
    model = unstack.load_model(copy)
    assert model is not unstack.load_model("paper")
    with pytest.raises(InvalidFile, match=r"missing\.skops"):
        unstack.load_model(tmp_path / "missing.skops")


def test_wrong_arguments_are_invalid_arguments(examples: Path) -> None:
    supports = unstack.load_supports(examples / "stack5.supports.json")
    with pytest.raises(
        InvalidArgument, match=r"stack5\.supports\.json: a model turns a scene into support probabilities"
    ):
        unstack.decide(supports, model="paper")
    with pytest.raises(ValueError, match="expected a Scene or Supports, got dict"):
        unstack.plan({"objects": []})  # type: ignore[arg-type]
    with pytest.raises(InvalidArgument, match="expected a Scene, got Supports"):
        unstack.support_probabilities(supports)  # type: ignore[arg-type]
    with pytest.raises(InvalidArgument, match="expected a model name or a model file path, got int"):
        unstack.load_model(3)  # type: ignore[arg-type]
    with pytest.raises(InvalidArgument, match="model must be a model name, a model file path or a SupportModel"):
        unstack.decide(unstack.load_scene(examples / "pile5.scene.json"), model=3.0)  # type: ignore[arg-type]
    with pytest.raises(InvalidArgument, match=r"stack5\.supports\.json: statics adjusts the probabilities a model"):
        unstack.decide(supports, statics=False)
    with pytest.raises(InvalidArgument, match="statics must be True or False, got 'no'"):
        unstack.support_probabilities(unstack.load_scene(examples / "scene3.json"), statics="no")  # type: ignore[arg-type]


def test_numpys_booleans_are_flags_like_pythons(examples: Path) -> None:
    import numpy as np

    scene = unstack.load_scene(examples / "pile5.scene.json")
    supports = unstack.load_supports(examples / "stack5.supports.json")
    assert unstack.decide(supports, statics=np.True_).choice == unstack.decide(supports).choice
    with pytest.raises(InvalidArgument, match=r"so statics=False would be ignored"):
        unstack.decide(supports, statics=np.False_)  # type: ignore[arg-type]
    flagged = unstack.decide(scene, statics=np.False_, physics_veto=np.False_)  # type: ignore[arg-type]
    assert flagged.to_dict() == unstack.decide(scene, statics=False).to_dict()


def test_statics_raises_the_box_leant_on_and_can_be_turned_off(examples: Path) -> None:
    scene = unstack.load_scene(examples / "leaning.scene.json")
    raised, kept = unstack.support_probabilities(scene), unstack.support_probabilities(scene, statics=False)
    upright, lean = raised.objects.index("upright"), raised.objects.index("lean")
    assert raised.probabilities[upright, lean] == 0.65 > kept.probabilities[upright, lean]
    changed = raised.probabilities != kept.probabilities
    assert changed.sum() == 1 and changed[upright, lean]
    order = unstack.plan(scene, seed=0).order
    assert order.index("lean") < order.index("upright")  # the leaning box comes off first


@pytest.mark.slow
@pytest.mark.parametrize(("found_probability", "warned"), [(0.3, True), (0.9, False)])
def test_a_statics_finding_the_consistent_worlds_make_unlikely_is_warned_about(
    found_probability: float, warned: bool
) -> None:
    finding = {"held": "top", "supporter": "side", "overhang_m": 0.03, "on_floor": False}
    supports = unstack.Supports(
        ["top", "side", "floor"],
        [[0.0, 0.2, 0.05], [found_probability, 0.0, 0.05], [0.9, 0.9, 0.0]],
        metadata={"tip_supports": [finding]},
    )
    from unstack.api import _statics_outweighed

    decision = _statics_outweighed(unstack.decide(supports, seed=0), supports)  # as decide on a scene does
    said = [
        warning for warning in decision.warnings if "statics found that 'top' cannot stand without 'side'" in warning
    ]
    assert bool(said) == warned
    if warned:
        final = decision.marginals[1, 0]
        assert f"P(side supports top) is {final:.2f}" in said[0] and final < 0.5


@pytest.mark.parametrize(
    "findings",
    [5, "xy", [{"supporter": "top"}], [{"supporter": "bottom", "held": "top"}]],
    ids=["number", "text", "no-held", "well-formed"],
)
def test_statics_findings_in_a_supports_files_metadata_are_not_read(findings: object) -> None:
    """A supports file's metadata is free-form: statics ran on no scene here, so nothing is said of it."""
    supports = unstack.Supports(["top", "bottom"], [[0.0, 0.1], [0.3, 0.0]], metadata={"tip_supports": findings})
    decision = unstack.decide(supports, seed=0)
    assert decision.choice == "top" and not any("statics" in warning for warning in decision.warnings)


def test_plan_from_a_scene_and_from_supports(examples: Path) -> None:
    plan = unstack.plan(unstack.load_scene(examples / "pile5.scene.json"), seed=0)
    assert sorted(plan.order) == sorted(plan.objects)
    supports = unstack.load_supports(examples / "stack5.supports.json")
    assert unstack.plan(supports).order[0] == unstack.decide(supports).choice


def test_validate_summarises_a_file(examples: Path) -> None:
    result = unstack.validate(examples / "pile5.scene.json")
    assert result.format == "unstack.scene/1" and "5 detected" in result.detail


def test_validate_counts_one_box_and_one_point_in_the_singular(tmp_path: Path) -> None:
    """It said '1 boxes, ..., 1 points'."""
    scene = unstack.Scene([unstack.Box("only", [0.4, 0.4, 0.4], [1.0, 0.0, 0.2])], [[1.0, 0.0, 0.4]], ["only"])
    scene.save(tmp_path / "one.json")
    assert unstack.validate(tmp_path / "one.json").detail == "1 box, 1 detected, 1 point"


def test_importing_unstack_and_deciding_on_supports_stays_light(repo: Path) -> None:
    code = (
        "import sys, unstack\n"
        "unstack.decide(unstack.load_supports('examples/stack5.supports.json'))\n"
        "print(' '.join(sorted(sys.modules)))"
    )
    env = {**os.environ, "PYTHONPATH": str(repo)}
    output = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True, cwd=repo, env=env)
    loaded = {name.split(".")[0] for name in output.stdout.split()}
    assert not loaded & {"sklearn", "numba", "networkx", "pybullet", "matplotlib", "pysat", "scipy"}, sorted(
        loaded & {"sklearn", "numba", "networkx", "pybullet", "matplotlib", "pysat", "scipy"}
    )
    assert "unstack.learning" not in output.stdout.split()


def test_the_public_api_is_listed_in_the_reference(repo: Path) -> None:
    reference = (repo / "docs" / "reference.md").read_text()
    for name in unstack.__all__:
        if name != "__version__":
            assert f"unstack.{name}" in reference, name


@pytest.mark.slow
def test_ranking_and_json_of_a_scene_decision(examples: Path) -> None:
    decision = unstack.decide(unstack.load_scene(examples / "pile5.scene.json"))
    ranking = decision.ranking()
    assert ranking[0][0] == decision.choice
    assert [cost for _, cost, _ in ranking[1:]] == sorted(cost for _, cost, _ in ranking[1:])
    document = json.loads(json.dumps(decision.to_dict()))
    assert document["choice"] == decision.choice and isinstance(document["warnings"], list)


@pytest.mark.slow  # the default model and the SAT listing of 6,942 worlds
def test_the_payoff_of_a_scene_agrees_with_the_decision_on_eq_11(examples: Path) -> None:
    from unstack.api import payoff

    scene = unstack.load(examples / "pile5.scene.json")
    table = payoff(scene)
    decision = unstack.decide(scene, cost="count", method="exact")
    assert len(table.worlds) == 6942 and table.objects == decision.objects
    np.testing.assert_allclose(table.expected_costs(), decision.expected_costs, atol=1e-9)


def test_a_payoff_of_supports_takes_no_model() -> None:
    from unstack.api import payoff

    with pytest.raises(InvalidArgument, match="the model would be ignored"):
        payoff(unstack.Supports(["a", "b"], [[0, 0.2], [0.7, 0]]), "general")


@pytest.mark.parametrize("path", [None, 123, ["pile.json"]])
@pytest.mark.parametrize("reader", [unstack.load, unstack.validate])
def test_a_path_that_is_not_one_is_an_invalid_argument(reader: Any, path: Any) -> None:
    with pytest.raises(
        InvalidArgument, match=f"expected a file name \\(a str or path-like\\), got {type(path).__name__}"
    ):
        reader(path)


def test_the_constructors_refuse_what_is_not_theirs_with_the_path() -> None:
    from unstack.errors import InvalidScene, InvalidSupports

    with pytest.raises(InvalidSupports, match=r"\$\.probabilities: expected real numbers, got dtype complex128"):
        unstack.Supports(["a", "b"], np.array([[0, 0.1j], [0.2, 0]]))
    with pytest.raises(InvalidScene, match=r"\$\.size\[0\]: expected a real number"):
        unstack.Box("a", np.array([0.4, 0.4, 0.4 + 0.5j]), [0.0, 0.0, 0.2])
    with pytest.raises(
        InvalidSupports, match=r"\$\.metadata: expected an object \(a dict with string keys\), got list"
    ):
        unstack.Supports(["a", "b"], [[0, 0.1], [0.2, 0]], metadata=[1, 2])  # type: ignore[arg-type]
    with pytest.raises(InvalidScene, match=r"\$\.boxes\[0\]: expected a Box, got dict"):
        unstack.Scene([{"id": "a"}], [], ["a"])  # type: ignore[list-item]


def test_an_out_of_distribution_warning_names_the_boxes_in_most_of_its_pairs() -> None:
    rng = np.random.default_rng(0)
    boxes = [unstack.Box(f"b{k}", [0.4, 0.3, 0.3], [1.0 + 0.45 * k, 0.0, 0.15]) for k in range(3)]
    boxes.append(unstack.Box("tower", [0.4, 0.4, 4.0], [1.0, 0.6, 2.0]))  # a 4 m box: no training pile has one
    cloud = rng.uniform([0.5, -0.5, 0.0], [2.5, 1.0, 1.0], (500, 3))
    supports = unstack.support_probabilities(unstack.Scene(boxes, cloud, [box.id for box in boxes]))
    [warning] = [text for text in supports.metadata["warnings"] if "out of distribution" in text]
    assert "The boxes in most of those pairs: 'tower' (" in warning
    assert "check their poses and sizes" in warning and "unstack train" in warning
