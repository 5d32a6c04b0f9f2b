"""Physics on the belief vetoes the default pick (unstack.physics_veto; the physics engine runs)."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest
from jsonschema import Draft202012Validator

import unstack
from tests.conftest import assert_one_line_error
from tests.conftest import unstack as run_unstack
from unstack.errors import InvalidArgument, UnstackError
from unstack.geometry import bounding_boxes
from unstack.height_veto import FREE_COST
from unstack.jsonio import load_schema
from unstack.physics_veto import PHYSICS_VETO, physics_veto
from unstack.scene import Box, Scene
from unstack.sim.belief import restless_boxes

pytestmark = pytest.mark.slow  # belief worlds in the physics engine

REPO = Path(__file__).resolve().parents[1]
PILE5 = REPO / "examples" / "pile5.scene.json"


def _vetoed_on_every_pile(folder: Path) -> list[tuple[Scene, unstack.Decision, unstack.Decision]]:
    piles = [unstack.load(path) for path in sorted(folder.glob("config-*.json"))]
    return [(scene, unstack.decide(scene, seed=0), unstack.decide(scene, seed=0, physics_veto=True)) for scene in piles]


def test_a_pick_the_belief_expects_to_move_nothing_is_kept() -> None:
    scene = unstack.load(PILE5)
    default = unstack.decide(scene, seed=0)
    kept = unstack.decide(scene, seed=0, physics_veto=True)
    assert kept.choice == default.choice
    assert kept.physics_veto is not None and not kept.physics_veto["vetoed"]
    assert [item["box"] for item in kept.physics_veto["tried"]] == [default.choice]
    assert kept.physics_veto["tried"][0]["expected_moved"] < PHYSICS_VETO


def test_a_vetoed_pick_goes_to_the_box_holding_nothing_up_expected_to_move_fewest(small_dataset: Path) -> None:
    vetoes = 0
    for scene, default, decided in _vetoed_on_every_pile(small_dataset):
        record = decided.physics_veto
        assert record is not None
        tried = {item["box"]: item["expected_moved"] for item in record["tried"]}
        assert record["tried"][0]["box"] == default.choice
        assert record["vetoed"] == (tried[default.choice] >= PHYSICS_VETO)
        if not record["vetoed"]:
            assert decided.choice == default.choice and list(tried) == [default.choice]
            continue
        vetoes += 1
        assert record.get("restless", []) == list(restless_boxes(scene))  # the record is the rest check
        costs = dict(zip(default.objects, default.expected_costs, strict=True))
        free = {box for box in default.objects if costs[box] < FREE_COST} - {default.choice}
        assert set(tried) == free | {default.choice}
        resting = {box: bounding_boxes([scene.box(box)])[0, 2] for box in tried}
        assert decided.choice == min(tried, key=lambda box: (tried[box], -resting[box], box))
    assert vetoes >= 1, "no pile of the small data set has a pick the belief vetoes"


def test_a_lower_veto_vetoes_whatever_the_default_veto_does_and_is_recorded(small_dataset: Path) -> None:
    scene = unstack.load(small_dataset / "config-0005.json")
    default = unstack.decide(scene, seed=0)
    usual, low = (physics_veto(default, scene, seed=0, veto_at=level) for level in (PHYSICS_VETO, 0.25))
    assert low.physics_veto is not None and usual.physics_veto is not None
    assert low.physics_veto["veto_at"] == 0.25 and usual.physics_veto["veto_at"] == PHYSICS_VETO
    assert low.physics_veto["tried"][0] == usual.physics_veto["tried"][0]  # the same worlds for the pick
    assert low.physics_veto["vetoed"] >= usual.physics_veto["vetoed"]
    with pytest.raises(InvalidArgument, match="veto_at must be positive"):
        physics_veto(default, scene, veto_at=0.0)
    with pytest.raises(InvalidArgument, match="worlds must be a positive integer, got 0"):
        physics_veto(default, scene, worlds=0)
    with pytest.raises(InvalidArgument, match="net must be True or False, got 1"):
        physics_veto(default, scene, net=1)  # type: ignore[arg-type]
    netted = physics_veto(default, scene, seed=0, net=True)
    assert netted.physics_veto is not None and netted.physics_veto["net"] is True
    assert "net" not in usual.physics_veto
    Draft202012Validator(load_schema("unstack.decision/1")).validate(netted.to_dict())


def test_the_veto_in_worlds_of_hidden_cartons_is_recorded_and_an_unknown_fill_refused(small_dataset: Path) -> None:
    scene = unstack.load(small_dataset / "config-0005.json")
    default = unstack.decide(scene, seed=0)
    cartons = physics_veto(default, scene, seed=0, fill="cartons")
    assert cartons.physics_veto is not None and cartons.physics_veto["fill"] == "cartons"
    assert cartons.physics_veto["tried"][0]["box"] == default.choice
    assert cartons.to_dict() == physics_veto(default, scene, seed=0, fill="cartons").to_dict()
    Draft202012Validator(load_schema("unstack.decision/1")).validate(cartons.to_dict())
    for fill in ("cloud", "boxes"):
        with pytest.raises(
            InvalidArgument, match=f"unknown belief fill '{fill}' for the physics veto; expected one of"
        ):
            physics_veto(default, scene, fill=fill)


def test_worlds_that_draw_masses_are_recorded_reproducible_and_try_the_same_pick(small_dataset: Path) -> None:
    scene = unstack.load(small_dataset / "config-0005.json")
    default = unstack.decide(scene, seed=0)
    typical = physics_veto(default, scene, seed=0)
    drawn = physics_veto(default, scene, seed=0, draw_masses=True)
    assert drawn.physics_veto is not None and drawn.physics_veto["masses_drawn"] is True
    assert typical.physics_veto is not None and "masses_drawn" not in typical.physics_veto
    assert drawn.physics_veto["tried"][0]["box"] == typical.physics_veto["tried"][0]["box"] == default.choice
    assert drawn.to_dict() == physics_veto(default, scene, seed=0, draw_masses=True).to_dict()
    Draft202012Validator(load_schema("unstack.decision/1")).validate(drawn.to_dict())
    with pytest.raises(InvalidArgument, match="draw_masses must be True or False, got 1"):
        physics_veto(default, scene, draw_masses=1)  # type: ignore[arg-type]


def test_the_same_seed_gives_the_same_worlds_and_choice(small_dataset: Path) -> None:
    scene = unstack.load(small_dataset / "config-0005.json")
    first, second = (unstack.decide(scene, seed=3, physics_veto=True).to_dict() for _ in range(2))
    assert first == second


def test_the_decision_json_records_the_veto_within_its_schema(small_dataset: Path) -> None:
    document = unstack.decide(unstack.load(small_dataset / "config-0005.json"), seed=0, physics_veto=True).to_dict()
    Draft202012Validator(load_schema("unstack.decision/1")).validate(document)
    assert document["physics_veto"]["worlds"] == 4 and document["physics_veto"]["fill"] == "faces"


@pytest.mark.parametrize(
    "high, doubt",
    [
        (Box("high", [0.4, 0.4, 0.3], [1.0, 0.3, 0.75]), "'high' floats 0.60 m up"),  # nothing under it
        (Box("high", [0.4, 0.4, 0.3], [1.0, 0.1, 0.2]), "'low' and 'high' overlap (42 %)"),  # into 'low'
    ],
)
def test_poses_that_cannot_stand_keep_the_reasoners_pick_without_physics(high: Box, doubt: str) -> None:
    low = Box("low", [0.4, 0.4, 0.3], [1.0, -0.1, 0.15])
    scene = Scene([low, high], np.zeros((0, 3)), ["low", "high"], source="fit.json")
    default = unstack.decide(scene, seed=0)
    kept = unstack.decide(scene, seed=0, physics_veto=True)
    assert kept.choice == default.choice and kept.physics_veto is not None
    assert kept.physics_veto["skipped"] == [doubt] and kept.physics_veto["tried"] == []
    assert not kept.physics_veto["vetoed"]
    assert any(
        warning.startswith(f"physics veto: not applied: poses of the scene cannot stand as reported ({doubt})")
        for warning in kept.warnings
    )
    Draft202012Validator(load_schema("unstack.decision/1")).validate(kept.to_dict())


def test_support_probabilities_and_the_moves_cost_are_refused() -> None:
    supports = unstack.load(REPO / "examples" / "stack5.supports.json")
    with pytest.raises(InvalidArgument, match="physics veto builds the boxes' poses"):
        unstack.decide(supports, physics_veto=True)
    with pytest.raises(InvalidArgument, match="not the moves cost"):
        unstack.decide(unstack.load(PILE5), cost="moves", physics_veto=True)


def test_a_box_outside_the_container_is_refused_with_the_container_it_would_need() -> None:
    boxes = [Box("inside", [0.4, 0.4, 0.4], [1.0, 0.0, 0.2]), Box("beyond", [0.4, 0.4, 0.4], [1.0, 3.0, 0.2])]
    scene = Scene(boxes, np.zeros((0, 3)), ["inside", "beyond"], source="far.json")
    decision = unstack.decide(scene, seed=0)
    with pytest.raises(
        InvalidArgument,
        match=r"far.json: box 'beyond' lies outside the container .* y within 1.175 m .* by 2.03 m, more than its own",
    ):
        physics_veto(decision, scene)
    with pytest.raises(InvalidArgument, match=r"boxes \['ghost'\] are not detected"):
        physics_veto(dataclasses.replace(decision, objects=("ghost", "inside")), scene)


def test_a_box_reaching_into_a_wall_is_slid_inside_recorded_and_warned_about() -> None:
    # 'side' reaches 0.10 m into the wall at y = -1.175 (a camera's fit of a box seen in part)
    boxes = [Box("low", [0.4, 0.4, 0.3], [1.0, 0.0, 0.15]), Box("side", [0.4, 0.4, 0.3], [1.0, -1.075, 0.15])]
    scene = Scene(boxes, np.zeros((0, 3)), ["low", "side"], source="wall.json")
    decided = unstack.decide(scene, seed=0, physics_veto=True)
    assert decided.physics_veto is not None
    assert decided.physics_veto["slid_inside"] == {"side": pytest.approx(0.10, abs=1e-9)}
    assert any("slid inside for the belief worlds (side 0.10 m)" in warning for warning in decided.warnings)
    Draft202012Validator(load_schema("unstack.decision/1")).validate(decided.to_dict())
    nearly = Scene([boxes[0], Box("side", [0.4, 0.4, 0.3], [1.0, -0.99, 0.15])], np.zeros((0, 3)), ["low", "side"])
    assert "slid_inside" not in unstack.decide(nearly, seed=0, physics_veto=True).physics_veto  # within 2 cm


def test_a_deeper_container_is_read_from_the_scene_and_a_wrong_one_refused() -> None:
    boxes = [Box("low", [0.4, 0.4, 0.3], [9.0, 0.0, 0.15]), Box("top", [0.4, 0.4, 0.3], [9.0, 0.0, 0.45])]
    shallow = Scene(boxes, np.zeros((0, 3)), ["low", "top"], source="deep.json")
    with pytest.raises(InvalidArgument, match=r"deep.json: box 'low' lies outside .* metadata.container"):
        unstack.decide(shallow, seed=0, physics_veto=True)
    deep = dataclasses.replace(shallow, metadata={"container": {"depth": 12.0, "width": 2.35, "height": 2.39}})
    decided = unstack.decide(deep, seed=0, physics_veto=True)
    assert decided.choice == "top" and decided.physics_veto is not None and not decided.physics_veto["vetoed"]
    wrong = dataclasses.replace(shallow, metadata={"container": {"depth": -1.0, "width": 2.35, "height": 2.39}})
    with pytest.raises(UnstackError, match=r"deep.json: \$\.metadata\.container\.depth: expected a positive extent"):
        unstack.decide(wrong, seed=0, physics_veto=True)


@pytest.mark.parametrize(
    ("container", "message"),
    [
        (
            {"depth": 2000.0, "width": 2.35, "height": 2.39},
            r"\.container\.depth: expected a positive extent of at most 100",
        ),
        ({"depth": 2.0, "width": 2.35, "height": 0.3}, r"\.container: a container of 2 x 2.35 x 0.3 m is smaller than"),
    ],
)
def test_a_container_in_another_unit_or_smaller_than_a_carton_is_refused(container: dict, message: str) -> None:
    box = Box("low", [0.4, 0.4, 0.3], [0.5, 0.0, 0.15])
    scene = Scene([box], np.zeros((0, 3)), ["low"], metadata={"container": container}, source="odd.json")
    with pytest.raises(UnstackError, match=r"odd.json: \$\.metadata" + message):
        unstack.decide(scene, seed=0, physics_veto=True)


def test_a_pallet_smaller_than_the_simulators_section_is_decided_with_its_own_extent() -> None:
    boxes = [Box("low", [0.4, 0.3, 0.3], [0.5, 0.0, 0.15]), Box("top", [0.4, 0.3, 0.3], [0.5, 0.0, 0.45])]
    pallet = {"container": {"depth": 1.2, "width": 1.0, "height": 2.0}}
    decided = unstack.decide(Scene(boxes, np.zeros((0, 3)), ["low", "top"], metadata=pallet), seed=0, physics_veto=True)
    assert decided.choice == "top" and decided.physics_veto is not None


def test_a_scene_metres_out_of_the_door_is_refused_as_another_frame() -> None:
    boxes = [Box("low", [0.4, 0.4, 0.3], [-3.9, 0.0, 0.15]), Box("top", [0.4, 0.4, 0.3], [-3.9, 0.0, 0.45])]
    scene = Scene(boxes, np.zeros((0, 3)), ["low", "top"], source="before.json")
    with pytest.raises(InvalidArgument, match=r"before.json: box 'low' lies outside .* \(x from -2 m before the door"):
        unstack.decide(scene, seed=0, physics_veto=True)


WITHOUT_PYBULLET = """
import sys
sys.modules["pybullet"] = None  # as if it were not installed: importing it raises ImportError
sys.argv = ["unstack", "decide", {file!r}, "--physics-veto"]
from unstack.cli.main import main
main()
"""


def test_without_the_physics_engine_the_veto_is_one_line_saying_what_to_install() -> None:
    import subprocess
    import sys

    probe = WITHOUT_PYBULLET.format(file=str(PILE5))
    result = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, timeout=300, cwd=REPO)
    assert_one_line_error(result, "pip install 'unstack[sim]'")


def test_the_cli_says_what_the_belief_expects_and_refuses_a_supports_file(small_dataset: Path) -> None:
    vetoed = run_unstack("decide", str(small_dataset / "config-0005.json"), "--physics-veto", "--seed", "0")
    assert vetoed.returncode == 0, vetoed.stderr
    said = " ".join(vetoed.stdout.split())  # as rich wraps it on an 80-column terminal
    assert said.startswith("Unload first: b06 (tied with b04: expected to move as few in the belief; the box resting")
    assert "physics on what the robot sees: in 4 belief worlds taking b05 moved 1.00 boxes on average" in said
    assert "vetoed; tried instead b04 0.00, b06 0.00; b06 moves the fewest" in said
    refused = run_unstack("decide", "examples/stack5.supports.json", "--physics-veto")
    assert refused.returncode == 2 and refused.stderr.count("\n") == 1
    assert "physics veto builds the boxes' poses" in refused.stderr
