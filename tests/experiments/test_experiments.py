"""Experiments: Table I against the paper, decision scores on simulated ISets."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from tests.conftest import assert_one_line_error, unstack
from unstack.experiments.decisions import (
    DECISION_MAKERS,
    IsetOutcome,
    decision_scores,
    evaluate_decisions,
    squared_regret,
)
from unstack.experiments.table1 import OEIS_A000798, PAPER_TABLE_I, table1
from unstack.learning.model_file import default_model_path, load_model


def test_table1_reproduces_the_paper() -> None:
    for row in table1(sizes=(3, 4, 5, 6), sat_max=5):
        assert row["exact"] == PAPER_TABLE_I[row["n"]] == OEIS_A000798[row["n"]]
        assert row.get("sat", row["exact"]) == row["exact"]
        assert row["all_worlds"] == 2 ** (row["n"] * (row["n"] - 1))


def handmade(costs: list[float], picks: dict[str, int]) -> IsetOutcome:
    r = len(costs)
    disturbance = np.column_stack([np.arange(r), np.arange(r) * 0.1])
    return IsetOutcome("x", [f"b{k}" for k in range(r)], np.array(costs), picks, disturbance, 1.0, 0.0, 0.0)


def test_random_scores_are_exact_expectations() -> None:
    iset = handmade([2.0, 0.0, 1.0], {"reasoner": 1, "priors": 0, "highest": 2, "free": 1})
    random = decision_scores([iset], "random")
    assert random["squared_regret"][0] == pytest.approx((4 + 0 + 1) / 3)
    assert random["first_pick_right"][0] == pytest.approx(1 / 3)
    assert random["moved"][0] == pytest.approx(1.0)
    chosen = decision_scores([iset], "priors")
    assert chosen["squared_regret"][0] == squared_regret(iset.costs, 0) == 4.0
    assert chosen["first_pick_right"][0] == 0.0 and chosen["moved"][0] == 0


@pytest.mark.slow  # runs experiments on a simulated data set
def test_decisions_on_simulated_piles(small_dataset: Path) -> None:
    result = evaluate_decisions(small_dataset, load_model(default_model_path()), r=4, isets=12, seed=2)
    assert result["isets"] == 12
    for maker in DECISION_MAKERS:
        summary = result["summary"][maker]
        assert summary["mse_cost"] >= 0 and 0 <= summary["first_pick_right"] <= 1
    for rows in result["bins"].values():
        assert sum(row["isets"] for row in rows) == 12
    for maker, differences in result["against_reasoner"].items():
        gap = result["summary"][maker]["boxes_moved"] - result["summary"]["reasoner"]["boxes_moved"]
        assert differences["boxes_moved"]["mean"] == pytest.approx(gap)
        assert differences["boxes_moved"]["standard_error"] >= 0
    again = evaluate_decisions(small_dataset, load_model(default_model_path()), r=4, isets=12, seed=2)
    assert again["summary"] == result["summary"]


@pytest.mark.slow  # runs experiments on a simulated data set
def test_decisions_with_isets_larger_than_the_piles_say_the_sizes_drawn(small_dataset: Path) -> None:
    """evaluate and fig5a warned of this; decisions reported "ISets of 50 boxes" without a word."""
    with pytest.warns(UserWarning, match=r"r = 50 is more than some piles can give: 2 of the 2 ISets hold"):
        evaluate_decisions(small_dataset, load_model(default_model_path()), r=50, isets=2, seed=2)


@pytest.mark.slow  # runs experiments on a simulated data set
def test_per_iset_records_pair_two_models_on_the_same_isets(small_dataset: Path) -> None:
    from unstack.api import load_model
    from unstack.experiments.decisions import paired_between_runs

    default = evaluate_decisions(small_dataset, load_model(default_model_path()), r=4, isets=8, seed=2)
    extended = evaluate_decisions(small_dataset, load_model("extended"), r=4, isets=8, seed=2)
    assert [row["boxes"] for row in default["per_iset"]] == [row["boxes"] for row in extended["per_iset"]]
    for row in default["per_iset"]:
        assert row["picks"]["reasoner"] in row["boxes"] and len(row["costs"]) == 4
    moved = np.array([row["moved"]["reasoner"] for row in default["per_iset"]])
    assert moved.mean() == pytest.approx(default["summary"]["reasoner"]["boxes_moved"])
    paired = paired_between_runs(default, extended)
    gap = extended["summary"]["reasoner"]["boxes_moved"] - default["summary"]["reasoner"]["boxes_moved"]
    assert paired["mean"] == pytest.approx(gap)
    with pytest.raises(ValueError, match="drew their ISets differently \\(seed\\)"):
        paired_between_runs(default, {**extended, "seed": 3})
    broken = {**extended, "per_iset": [{"scene": "s"}]}
    with pytest.raises(ValueError, match=r"per-ISet records are not those of a decisions\.json"):
        paired_between_runs(default, broken)
    with pytest.raises(ValueError, match="no per-ISet records"):
        paired_between_runs(default, {key: value for key, value in extended.items() if key != "per_iset"})


@pytest.mark.parametrize("spelling", ["./piles", "piles/", "other/../piles"])
def test_runs_on_the_same_folder_spelt_differently_pair(spelling: str) -> None:
    from unstack.experiments.decisions import paired_between_runs

    run = {"data": "piles", "r": 2, "seed": 0, "draw": "random",
           "per_iset": [{"scene": "s", "boxes": ["a", "b"], "moved": {"reasoner": 2.0}}]}  # fmt: skip
    other = {**run, "data": spelling, "per_iset": [{"scene": "s", "boxes": ["a", "b"], "moved": {"reasoner": 0.5}}]}
    assert paired_between_runs(run, other)["mean"] == pytest.approx(-1.5)
    with pytest.raises(ValueError, match=r"drew their ISets differently \(data\)"):
        paired_between_runs(run, {**other, "data": "piles2"})


def test_runs_with_data_digests_pair_by_the_data_not_the_folders_name() -> None:
    """The same data given by an absolute path was refused as other data; two folders of one name passed."""
    from unstack.experiments.decisions import paired_between_runs

    rows = [{"scene": "s", "boxes": ["a", "b"], "moved": {"reasoner": 2.0}}]
    run = {"data": "piles", "data_sha256": "ab", "r": 2, "seed": 0, "draw": "random", "per_iset": rows}
    assert paired_between_runs(run, {**run, "data": "/elsewhere/piles"})["mean"] == 0.0
    with pytest.raises(ValueError, match=r"drew their ISets differently \(data\)"):
        paired_between_runs(run, {**run, "data_sha256": "cd"})


@pytest.mark.slow  # a subprocess
def test_pairing_with_a_run_of_another_r_is_refused_before_the_run(small_dataset: Path, tmp_path: Path) -> None:
    earlier = tmp_path / "decisions.json"
    earlier.write_text(json.dumps({"data": str(small_dataset), "r": 3, "seed": 0, "draw": "random", "per_iset": []}))
    result = unstack("experiment", "decisions", str(small_dataset), "--out", str(tmp_path / "out"), "--r", "4",
                     "--pair-with", str(earlier))  # fmt: skip
    assert result.returncode == 2 and "the runs drew their ISets differently (r)" in result.stderr, result.stderr
    assert not (tmp_path / "out").exists()


@pytest.mark.slow  # runs experiments on a simulated data set
def test_experiment_commands(small_dataset: Path, tmp_path: Path) -> None:
    result = unstack("experiment", "table1", "--out", str(tmp_path), "--max-n", "5")
    assert result.returncode == 0, result.stderr
    assert [row["exact"] for row in json.loads((tmp_path / "table1.json").read_text())] == [29, 355, 6942]
    result = unstack("experiment", "table1", "--out", str(tmp_path), "--full")
    assert result.returncode == 0, result.stderr
    assert [row["n"] for row in json.loads((tmp_path / "table1.json").read_text())] == [3, 4, 5, 6, 7]
    result = unstack("experiment", "decisions", str(small_dataset), "--out", str(tmp_path), "--r", "4", "--isets", "6")
    assert result.returncode == 0, result.stderr
    assert (tmp_path / "fig4.png").read_bytes()[:4] == b"\x89PNG"
    assert json.loads((tmp_path / "decisions.json").read_text())["isets"] == 6
    assert json.loads((tmp_path / "decisions.json").read_text())["statics"] is True
    first = tmp_path / "first.json"
    (tmp_path / "decisions.json").rename(first)
    common = ("experiment", "decisions", str(small_dataset), "--out", str(tmp_path), "--r", "4", "--isets", "6")
    result = unstack(*common, "--model", "extended", "--pair-with", str(first))
    assert result.returncode == 0, result.stderr
    assert f"this run minus {first}:" in result.stdout
    assert json.loads((tmp_path / "decisions.json").read_text())["against_earlier_run"]["file"] == str(first)
    result = unstack(*common, "--no-statics", "--pair-with", str(first))  # the same ISets: they pair
    assert result.returncode == 0, result.stderr
    without = json.loads((tmp_path / "decisions.json").read_text())
    assert without["statics"] is False and without["against_earlier_run"]["file"] == str(first)
    result = unstack(*common, "--seed", "5", "--pair-with", str(first))
    assert result.returncode == 2 and result.stderr.strip().endswith(
        "drew their ISets differently (seed): nothing to pair"
    )


@pytest.mark.slow  # runs experiments on a simulated data set
@pytest.mark.parametrize(
    ("arguments", "message"),
    [
        (["table1", "--out", "{tmp}", "--max-n", "12"], "Invalid value for '--max-n': max_n must be at most 8, got 12"),
        (["decisions", "examples", "--out", "{tmp}"], "examples: expected a data set folder with config-NNNN.json"),
        (
            ["decisions", "examples", "--out", "{tmp}", "--r", "1"],
            "Invalid value for '--r': r must be at least 2, got 1",
        ),
        (["unload", "examples", "--out", "{tmp}"], "examples: expected a data set folder with config-NNNN.json"),
        (["fig5a", "{data}", "--out", "{tmp}", "--full"], "the paper's size is 200 configurations and 10 folds"),
        (["unload", "{data}", "--out", "{tmp}", "--scheduler", "nowhere"], "expected an address like tcp://HOST:PORT"),
        (
            ["train-disturbance", "{tmp}", "--out", "{tmp}/results"],
            "no collected states (unstack experiment pick-responses writes them)",
        ),
        (
            ["decisions", "{data}", "--out", "{tmp}", "--pair-with", "examples/pile5.scene.json"],
            "examples/pile5.scene.json: expected the decisions.json of an `unstack experiment decisions` run",
        ),
    ],
)
def test_experiment_bad_input(arguments: list[str], message: str, tmp_path: Path, small_dataset: Path) -> None:
    result = unstack("experiment", *[argument.format(tmp=tmp_path, data=small_dataset) for argument in arguments])
    assert_one_line_error(result, message, nothing_written_in=tmp_path)


@pytest.mark.slow  # runs experiments on a simulated data set
@pytest.mark.parametrize(("split", "features"), [("pairs", "paper"), ("configuration", "extended")])
def test_fig5a_on_simulated_piles(small_dataset: Path, tmp_path: Path, split: str, features: str) -> None:
    result = unstack("experiment", "fig5a", str(small_dataset), "--out", str(tmp_path), "--r", "4", "--isets", "3",
                     "--cv", "3", "--split-by", split, "--features", features)  # fmt: skip
    assert result.returncode == 0, result.stderr
    assert "paper (Fig. 5a)" in result.stdout and "78.4 %" in result.stdout
    document = json.loads((tmp_path / "fig5a.json").read_text())
    matrix = np.array(document["validation"]["confusion_matrix"])
    assert matrix.sum() == document["validation"]["relations"]
    assert 0.0 < document["balanced_threshold"] <= 1.0 and 0.0 < document["paper_recall_threshold"] <= 1.0
    assert document["split_by"] == split and document["features"]["feature_set"] == features
    assert {key: document[key] for key in ("r", "isets", "seed", "cv")} == {"r": 4, "isets": 3, "seed": 0, "cv": 3}
    assert 2 <= document["cv_folds"] <= 3
    roc = document["validation_roc"]
    assert 0.0 <= roc["not_supp_recall_at_paper_supp_recall"] <= 1.0 and 0.0 <= roc["auc"] <= 1.0
    assert np.all(np.diff(roc["supp_recall"]) <= 0)  # a stricter not-SUPP recall never raises the SUPP recall
    assert (tmp_path / "fig5a.png").read_bytes()[:4] == b"\x89PNG"


@pytest.mark.slow  # runs experiments on a simulated data set
def test_real7_scores_every_iset(small_dataset: Path) -> None:
    from itertools import combinations

    from unstack.dataset_folders import list_configurations
    from unstack.experiments.real7 import real7
    from unstack.scene import load_scene

    boxes = len(load_scene(list_configurations(small_dataset)[0]).boxes)
    with pytest.warns(UserWarning, match=rf"1 of 1 piles are not of the paper's 7 boxes \(the first has {boxes}\)"):
        result = real7(small_dataset, load_model(default_model_path()), sizes=(3,), piles=1)
    assert result["by_r"]["3"]["isets"] == len(list(combinations(range(boxes), 3)))
    assert result["by_r"]["3"]["paper_first_pick_right"] == 0.905
    assert 0 <= result["by_r"]["3"]["reasoner"]["first_pick_right"] <= 1
    assert result["worst_mse"]["random"] >= 0


@pytest.mark.slow  # runs experiments on a simulated data set
def test_real7_command(small_dataset: Path, tmp_path: Path) -> None:
    result = unstack("experiment", "real7", str(small_dataset), "--out", str(tmp_path), "--piles", "1")
    assert result.returncode == 0, result.stderr
    assert "90.5 %" in result.stdout and "worst MSE(cost) over r" in result.stdout
    assert set(json.loads((tmp_path / "real7.json").read_text())["by_r"]) == {"3", "4", "5"}


@pytest.mark.slow  # runs experiments on a simulated data set
@pytest.mark.parametrize(("samples", "recorded"), [([], None), (["--samples", "64"], 64)], ids=["default", "given"])
def test_unload_with_a_time_limit_keeps_samples_given_with_it(
    small_dataset: Path, tmp_path: Path, samples: list[str], recorded: int | None
) -> None:
    """An explicit --samples with --time-limit was dropped without a word; the default still gives way."""
    result = unstack("experiment", "unload", str(small_dataset), "--out", str(tmp_path), "--configs", "1",
                     "--time-limit", "0.05", *samples)  # fmt: skip
    assert result.returncode == 0, result.stderr
    assert json.loads((tmp_path / "unloading.json").read_text())["samples"] == recorded


@pytest.mark.slow  # runs experiments on a simulated data set
def test_unload_command_executes_every_order(small_dataset: Path, tmp_path: Path) -> None:
    result = unstack("experiment", "unload", str(small_dataset), "--out", str(tmp_path), "--configs", "2",
                     "--time-limit", "0.1", "--closed-loop", "--no-statics", "--jobs", "2")  # fmt: skip
    assert result.returncode == 0, result.stderr
    document = json.loads((tmp_path / "unloading.json").read_text())
    assert document["statics"] is False
    assert document["makers"][-2:] == ["reasoner_closed_loop", "highest_closed_loop"]
    assert set(document["summary"]) == set(document["makers"])
    assert (tmp_path / "unloading.png").read_bytes()[:4] == b"\x89PNG"
    assert document["configs"] == 2
    for pile in document["piles"]:
        orders = [run["order"] for run in pile["runs"].values()]
        assert all(sorted(order) == sorted(orders[0]) and len(order) == pile["detected"] for order in orders)
        for run in pile["runs"].values():
            assert run["boxes_moved"] == sum(len(step["moved"]) for step in run["steps"])
    highest = document["against_reasoner"]["highest"]["boxes_moved"]
    assert highest["mean"] == pytest.approx(
        document["summary"]["highest"]["boxes_moved_per_pile"] - document["summary"]["reasoner"]["boxes_moved_per_pile"]
    )


@pytest.mark.parametrize(("recall", "expected"), [(0.5, 0.8), (0.75, 0.6), (1.0, 0.3), (0.0, 0.9)])
def test_recall_threshold_is_the_largest_reaching_the_recall(recall: float, expected: float) -> None:
    from unstack.experiments.fig5a import recall_threshold

    truth = np.array([1, 1, 1, 1, 0, 0])
    probability = np.array([0.9, 0.8, 0.6, 0.3, 0.95, 0.1])
    threshold = recall_threshold(truth, probability, recall)
    assert threshold == expected
    assert np.mean(probability[truth == 1] >= threshold) >= recall


@pytest.mark.slow  # runs experiments on a simulated data set
def test_unloading_resumes_from_its_checkpoints(
    small_dataset: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import unstack.sim.unloading as simulator
    from unstack.experiments.unloading import unloading_experiment

    model = load_model(default_model_path())
    first = unloading_experiment(small_dataset, model, configs=1, samples=64, checkpoints=tmp_path)
    assert len(list(tmp_path.glob("*.json"))) == 1

    def no_simulation(*_: object, **__: object) -> None:
        raise AssertionError("a finished pile was simulated again")

    monkeypatch.setattr(simulator, "execute_unloading", no_simulation)
    again = unloading_experiment(small_dataset, model, configs=1, samples=64, checkpoints=tmp_path)
    assert again == first
    with pytest.raises(AssertionError, match="simulated again"):  # another seed is another run
        unloading_experiment(small_dataset, model, configs=1, samples=64, seed=5, checkpoints=tmp_path)
    assert first["statics"] is True
    with pytest.raises(AssertionError, match="simulated again"):  # so is a run without statics
        unloading_experiment(small_dataset, model, configs=1, samples=64, statics=False, checkpoints=tmp_path)


@pytest.mark.slow  # runs experiments on a simulated data set
def test_unloading_runs_on_a_dask_cluster(small_dataset: Path) -> None:
    from distributed import LocalCluster

    from unstack.experiments.unloading import unloading_experiment
    from unstack.sim.dataset import scheduler_client

    model = load_model(default_model_path())
    with (
        LocalCluster(n_workers=1, threads_per_worker=1, processes=True, dashboard_address=None) as cluster,
        scheduler_client(cluster.scheduler_address) as client,  # the command line's client: not the default one
    ):
        result = unloading_experiment(small_dataset, model, configs=2, samples=64, client=client)
    assert [pile["scene"] for pile in result["piles"]] == ["config-0000.json", "config-0001.json"]
    for pile in result["piles"]:
        assert all(sorted(run["order"]) == sorted(pile["runs"]["highest"]["order"]) for run in pile["runs"].values())


@pytest.mark.slow  # runs experiments on a simulated data set
def test_unloading_orders_are_reproducible_for_a_seed(small_dataset: Path) -> None:
    from unstack.experiments.unloading import DecisionSettings, unloading_orders
    from unstack.scene import load_scene

    scene = load_scene(sorted(small_dataset.glob("config-*.json"))[0])
    model = load_model(default_model_path())
    first = unloading_orders(scene, model, DecisionSettings(seed=3, samples=64))
    assert first == unloading_orders(scene, model, DecisionSettings(seed=3, samples=64))
    assert sorted(first["reasoner"]) == sorted(scene.detected)


def test_real7_rows_of_a_size_the_piles_do_not_hold_are_dashes() -> None:
    """An r of no ISet gave numpy's empty-mean warnings and 'nan %' in the table."""
    from unstack.experiments.real7 import summary_rows

    none = {maker: {"first_pick_right": None, "mse_cost": None, "boxes_moved": None} for maker in DECISION_MAKERS}
    some = {maker: {"first_pick_right": 0.5, "mse_cost": 1.0, "boxes_moved": 0.5} for maker in DECISION_MAKERS}
    result = {"by_r": {"4": {"isets": 2, **some, "paper_first_pick_right": 0.81},
                       "5": {"isets": 0, **none, "paper_first_pick_right": 0.62}}}  # fmt: skip
    assert summary_rows(result) == [
        ["4", "2", "81.0 %", "50.0 %", "50.0 %", "50.0 %"],
        ["5", "0", "62.0 %", "-", "-", "-"],
    ]


def test_the_bins_edges_are_written_as_their_decimals() -> None:
    """linspace's edges were written with float noise: 0.30000000000000004, 0.09999999999999999."""
    from unstack.experiments.decisions import BINS, _binned

    empty = {maker: {"squared_regret": np.zeros(0)} for maker in ("reasoner", "random")}
    binned = _binned([], empty)
    edges = [edge for rows in binned.values() for row in rows for edge in (row["low"], row["high"])]
    assert len(binned) == len(BINS) and all(len(repr(edge)) <= 5 for edge in edges), edges
