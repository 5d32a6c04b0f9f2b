"""Collecting what every pick would move, and training the disturbance model on it."""

from __future__ import annotations

import itertools
import json
from pathlib import Path

import numpy as np
import pytest

from unstack.errors import InvalidArgument
from unstack.experiments.disturbance_training import pick_scores, train_disturbance
from unstack.experiments.pick_causes import CAUSES, cause_table, moved_causes
from unstack.experiments.pick_responses import (
    BEHAVIOUR_SHARES,
    behaviour_pick,
    collect_pick_responses,
    load_states,
    pick_table,
)
from unstack.learning.model_file import default_model_path, load_model
from unstack.learning.pick_features import PICK_FEATURES
from unstack.scene import Box

pytestmark = pytest.mark.slow  # physics


@pytest.fixture(scope="module")
def states(small_dataset: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("states")
    collect_pick_responses([small_dataset], out, piles=2, seed=1, max_picks=3)
    return out


@pytest.fixture(scope="module")
def records(states: Path) -> list[dict[str, object]]:
    return pick_table(states, load_model(default_model_path()), seed=0, samples=64)


def test_every_state_is_saved_with_every_candidates_outcome(states: Path) -> None:
    loaded = list(load_states(states))
    assert len(loaded) == 6  # two piles, three picks each
    for header, scene in loaded:
        assert sorted(header["moved"]) == sorted(scene.detected) and scene.points.shape[1] == 3
        assert all(set(moved) <= set(header["ids"]) - {box} for box, moved in header["moved"].items())


def test_one_piles_folder_gives_its_own_states_in_order(states: Path) -> None:
    folder = sorted(path.parent for path in states.glob("*/*/done.json"))[1]
    headers = [header for header, _ in load_states(folder)]
    assert [header["step"] for header in headers] == [0, 1, 2] and {header["pile"] for header in headers} == {
        folder.name
    }


def test_the_probed_outcome_is_what_the_pick_then_does(small_dataset: Path) -> None:
    """The chosen candidate's probed outcome is the step the run then records, and a replay of
    the order without probes moves the same boxes (restoring a saved state keeps the poses
    and velocities but not the contact solver's warm start, so how far a falling box
    goes differs by centimetres)."""
    from unstack.scene import load_scene
    from unstack.sim.unloading import unload_container

    scene = load_scene(sorted(small_dataset.glob("config-*.json"))[0])
    probed: list[dict[str, object]] = []

    def worst_first(current: object, outcomes: dict[str, object]) -> str:
        choice = max(sorted(outcomes), key=lambda box_id: outcomes[box_id].boxes_moved)  # type: ignore[attr-defined]
        probed.append({"choice": choice, "moved": outcomes[choice].moved})  # type: ignore[attr-defined]
        return choice

    run = unload_container(scene, worst_first, max_picks=3, seed=0, probe=True)
    assert [step.moved for step in run.steps] == [record["moved"] for record in probed]
    order = iter(run.order)
    replay = unload_container(scene, lambda _current: next(order), max_picks=3, seed=0)  # no probes this time
    assert [step.moved for step in replay.steps] == [step.moved for step in run.steps]


def test_the_collection_resumes_without_work(small_dataset: Path, states: Path) -> None:
    before = sorted(path.stat().st_mtime_ns for path in states.glob("*/*/step-*.npz"))
    summaries = collect_pick_responses([small_dataset], states, piles=2, seed=1, max_picks=3)
    assert [summary["states"] for summary in summaries] == [3, 3]
    assert sorted(path.stat().st_mtime_ns for path in states.glob("*/*/step-*.npz")) == before


@pytest.mark.parametrize("change", [{"max_picks": 1}, {"seed": 2}], ids=["fewer-picks", "another-seed"])
def test_a_collection_resumed_with_other_settings_collects_again_and_keeps_no_old_state(
    small_dataset: Path, states: Path, tmp_path: Path, change: dict[str, int]
) -> None:
    """A pile counted as done whatever the settings, and steps of a longer run stayed beside a shorter one's."""
    import shutil

    out = tmp_path / "states"
    shutil.copytree(states, out)  # the module's collection: seed 1, three picks
    summaries = collect_pick_responses([small_dataset], out, piles=2, **{"seed": 1, "max_picks": 3, **change})
    fresh = collect_pick_responses(
        [small_dataset], tmp_path / "fresh", piles=2, **{"seed": 1, "max_picks": 3, **change}
    )
    assert [summary["states"] for summary in summaries] == [summary["states"] for summary in fresh]
    assert len(list(load_states(out))) == sum(summary["states"] for summary in fresh)


def test_a_decision_maker_as_behaviour_takes_every_pick(small_dataset: Path, tmp_path: Path) -> None:
    """With ``behaviour="highest"`` every saved state is followed by the removal of the box
    that maker picks there: the next state no longer holds it."""
    from unstack.experiments.container import container_policies

    highest = container_policies(None, seed=1, makers=["highest"])["highest"]
    summaries = collect_pick_responses([small_dataset], tmp_path, piles=1, seed=1, max_picks=3, behaviour="highest")
    assert summaries[0]["behaviour"] == "highest" and summaries[0]["states"] == 3
    loaded = [scene for _, scene in load_states(tmp_path)]
    for scene, after in itertools.pairwise(loaded):
        taken = highest(scene)
        assert taken in scene.box_ids and taken not in after.box_ids
        assert len(after.box_ids) == len(scene.box_ids) - 1


def test_models_given_to_the_drawn_behaviour_are_said_unused(small_dataset: Path, tmp_path: Path) -> None:
    """A support model given with behaviour 'mixed' was taken silently (the CLI did not even open the file)."""
    from unstack.learning.model_file import default_model_path, load_model

    with pytest.warns(UserWarning, match=r"the support model is not used: the picks are drawn \(behaviour 'mixed'\)"):
        collect_pick_responses(
            [small_dataset], tmp_path, piles=1, seed=1, max_picks=1, model=load_model(default_model_path())
        )
    collect_pick_responses([small_dataset], tmp_path / "plain", piles=1, seed=1, max_picks=1)
    assert len(list(load_states(tmp_path))) == len(list(load_states(tmp_path / "plain")))


def test_an_unknown_behaviour_is_refused(small_dataset: Path, tmp_path: Path) -> None:
    with pytest.raises(InvalidArgument, match="unknown behaviour 'tallest'; expected one of mixed, unstack"):
        collect_pick_responses([small_dataset], tmp_path, behaviour="tallest")
    assert not any(tmp_path.iterdir())


def test_each_state_gives_a_row_per_candidate_in_both_views(records: list[dict[str, object]]) -> None:
    assert len(records) == 12 and {record["view"] for record in records} == {"full", "missed"}
    for record in records:
        features = np.asarray(record["features"])
        assert features.shape == (len(record["candidates"]), len(PICK_FEATURES))  # type: ignore[arg-type]


def test_the_missed_view_detects_a_subset(records: list[dict[str, object]]) -> None:
    by_state: dict[object, dict[object, set[str]]] = {}
    for record in records:
        by_state.setdefault(record["state"], {})[record["view"]] = set(record["candidates"])  # type: ignore[arg-type]
    assert all(views["missed"] <= views["full"] and views["missed"] for views in by_state.values())


def test_training_reports_held_out_figures_and_the_lookahead_is_the_floor(records: list[dict[str, object]]) -> None:
    model, report = train_disturbance(records, folds=2, max_iter=20)
    assert report["piles"] == 2 and report["rows"] == sum(len(r["candidates"]) for r in records)  # type: ignore[arg-type]
    scores = report["pick_scores"]["all"]
    assert scores["lookahead"] <= min(scores["highest"], scores["load"], scores["moves"])
    assert model.expected_moves(np.zeros((1, len(PICK_FEATURES)))).shape == (1,)
    json.dumps(report)  # the report is JSON


def test_the_report_records_the_folds_used_not_those_asked_for(records: list[dict[str, object]]) -> None:
    """100 folds asked of 2 piles ran 2 (a pile a fold at most) and the report said 100."""
    _, report = train_disturbance(records, folds=100, max_iter=20)
    assert report["folds"] == report["piles"] == 2


def test_the_behaviour_takes_the_probe_best_the_highest_or_a_random_box() -> None:
    moved, resting = {"a": 3, "b": 0, "c": 1}, {"a": 0.6, "b": 0.0, "c": 0.3}
    assert behaviour_pick(moved, resting, 0.0) == "b"
    assert behaviour_pick(moved, resting, BEHAVIOUR_SHARES["lookahead"]) == "a"
    assert {behaviour_pick(moved, resting, 0.99, order) for order in range(3)} == {"a", "b", "c"}


def test_pick_scores_compare_the_policies_state_by_state() -> None:
    record = {"moved": np.array([2, 0]), "candidates": ["high", "low"], "default_choice": "low",
              "resting": np.array([0.3, 0.0]), "view": "full", "pile": "d-wall/c0", "state": "s"}  # fmt: skip
    scores = pick_scores([record], [np.array([0.0, 1.0])])
    assert scores["wall/full"] == {"highest": 2.0, "load": 0.0, "lookahead": 0.0, "moves": 2.0, "states": 1}


@pytest.mark.parametrize(
    ("position", "cause"),
    [([1.0, 0.0, 0.45], "held up"), ([1.0, 0.41, 0.15], "dragged"), ([2.0, 0.0, 0.15], "knocked")],
)
def test_a_moved_box_gets_the_cause_that_fits(position: list[float], cause: str) -> None:
    boxes = [Box("pick", [0.4, 0.4, 0.3], [1.0, 0.0, 0.15]), Box("other", [0.4, 0.4, 0.3], position)]
    assert moved_causes(boxes, "pick", ["other"]) == {"other": cause}


def test_the_cause_table_gives_shares_that_sum_to_one() -> None:
    boxes = [Box("pick", [0.4, 0.4, 0.3], [1.0, 0.0, 0.15]), Box("on", [0.4, 0.4, 0.3], [1.0, 0.0, 0.45]),
             Box("far", [0.4, 0.4, 0.3], [2.0, 0.0, 0.15])]  # fmt: skip
    table = cause_table([("wall/highest", boxes, "pick", ["on", "far"], ["pick", "on"])])["wall/highest"]
    assert sum(table[f"share_{name.replace(' ', '_')}"] for name in CAUSES) == pytest.approx(1.0)
    assert table["share_undetected"] == 0.5 and table["moved"] == 2


def test_two_data_sets_of_one_name_are_refused_before_any_state_is_written(small_dataset: Path, tmp_path: Path) -> None:
    import shutil

    from unstack.errors import InvalidArgument

    twin = tmp_path / "elsewhere" / small_dataset.name
    shutil.copytree(small_dataset, twin)
    with pytest.raises(InvalidArgument, match=rf"two data sets are both named '{small_dataset.name}'"):
        collect_pick_responses([small_dataset, twin], tmp_path / "states", piles=1, max_picks=1)
    assert not (tmp_path / "states").exists()


def test_a_second_collection_into_a_folder_being_written_is_refused(small_dataset: Path, tmp_path: Path) -> None:
    from unstack.atomic import folder_writer
    from unstack.errors import InvalidArgument

    (tmp_path / "states").mkdir()
    with folder_writer(tmp_path / "states", "states"), pytest.raises(InvalidArgument, match="another unstack run"):
        collect_pick_responses([small_dataset], tmp_path / "states", piles=1, max_picks=1)
