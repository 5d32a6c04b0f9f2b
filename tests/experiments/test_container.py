"""Emptying containers as a robot does, with every decision maker."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from tests.conftest import assert_one_line_error, unstack
from unstack.errors import UnstackError
from unstack.experiments.container import CONTAINER_MAKERS, container_experiment, container_policies
from unstack.learning.model_file import default_model_path, load_model
from unstack.scene import Box, Scene
from unstack.understanding.clouds import surface_cloud


@pytest.fixture(scope="module")
def result(small_dataset: Path) -> dict[str, object]:
    model = load_model(default_model_path())
    return container_experiment(small_dataset, model, piles=1, max_picks=1, samples=64, seed=2, makers=CONTAINER_MAKERS)


@pytest.mark.slow  # physics runs of every decision maker
def test_every_maker_picks_from_the_same_pile_up_to_the_pick_limit(result: dict[str, object]) -> None:
    assert result["makers"] == list(CONTAINER_MAKERS)
    runs = result["runs"][0]["runs"]  # type: ignore[index]
    for maker in CONTAINER_MAKERS:
        assert len(runs[maker]["order"]) == 1 and runs[maker]["stopped"] == "pick limit"
        assert all("fallen" in step for step in runs[maker]["steps"])
    summary = result["summary"]  # type: ignore[index]
    assert set(summary["unstack"]) == {  # type: ignore[index]
        "picks_per_pile", "boxes_moved_per_pile", "boxes_fallen_per_pile", "calm_picks_per_pile", "boxes_moved_per_pick",
    }  # fmt: skip
    assert set(result["against_unstack"]) == set(CONTAINER_MAKERS) - {"unstack"}  # type: ignore[arg-type]


@pytest.mark.slow  # physics runs of every decision maker
def test_the_lookahead_first_pick_moves_no_more_than_any_other_makers(result: dict[str, object]) -> None:
    runs = result["runs"][0]["runs"]  # type: ignore[index]
    first = {maker: runs[maker]["steps"][0]["boxes_moved"] for maker in CONTAINER_MAKERS}
    assert first["lookahead"] == min(first.values()), first


@pytest.mark.slow  # physics runs of every decision maker
def test_an_unknown_maker_is_refused_before_any_work(small_dataset: Path) -> None:
    with pytest.raises(UnstackError, match=r"unknown decision makers \['tallest'\]"):
        container_experiment(small_dataset, load_model(default_model_path()), makers=("unstack", "tallest"))


@pytest.mark.slow  # physics runs of a decision maker
@pytest.mark.parametrize(
    ("given", "message"),
    [
        ({"occupancy": 0.5}, r"occupancy 0\.5 is not used: only belief_sampled, belief_sampled_veto read it"),
        ({"disturbance": "any.skops"}, r"the disturbance model is not used: only moves, moves_veto, "),
    ],
    ids=["occupancy", "disturbance"],
)
def test_a_setting_no_maker_reads_is_said_unused_and_not_recorded(
    small_dataset: Path, tmp_path: Path, given: dict[str, object], message: str
) -> None:
    """They were accepted silently, recorded among the run's settings and joined its checkpoints' key."""
    with pytest.warns(UserWarning, match=message):
        result = container_experiment(
            small_dataset,
            load_model(default_model_path()),
            piles=1,
            max_picks=1,
            seed=2,
            makers=("highest",),
            checkpoints=tmp_path,
            **given,  # type: ignore[arg-type]
        )
    [checkpoint] = tmp_path.glob("config-*.json")
    key = json.loads(checkpoint.read_text())["key"]
    assert result["occupancy"] is None and "occupancy" not in key and "disturbance_sha256" not in key


@pytest.mark.slow  # physics runs of every decision maker
def test_the_cli_writes_the_results_and_resumes(small_dataset: Path, tmp_path: Path) -> None:
    arguments = ["experiment", "container", str(small_dataset), "--out", str(tmp_path), "--piles", "1",
                 "--makers", "unstack,highest", "--max-picks", "1", "--samples", "64"]  # fmt: skip
    first = unstack(*arguments)
    assert first.returncode == 0, first.stderr
    assert "highest" in first.stdout and "container.json" in first.stdout
    document = json.loads((tmp_path / "container.json").read_text())
    assert document["makers"] == ["unstack", "highest"] and document["piles"] == 1
    again = unstack(*arguments)
    assert again.returncode == 0, again.stderr
    assert json.loads((tmp_path / "container.json").read_text())["runs"] == document["runs"]
    bad = unstack("experiment", "container", str(small_dataset), "--out", str(tmp_path), "--makers", "tallest")
    assert bad.returncode == 2 and bad.stderr.count("\n") == 1 and "unknown decision makers" in bad.stderr


def _tall_loaded_and_short_free() -> Scene:
    boxes = [
        Box("loaded", [0.4, 0.4, 0.6], [1.2, -0.35, 0.301]),
        Box("unseen", [0.4, 0.4, 0.3], [1.2, -0.35, 0.752]),
        Box("free", [0.4, 0.4, 0.3], [1.2, 0.35, 0.151]),
    ]
    return Scene(boxes, surface_cloud(boxes, viewpoint=[-2.0, 0.0, 1.5], seed=0), ["loaded", "free"])


@pytest.mark.slow  # physics runs of every decision maker
def test_the_hybrid_takes_the_highest_box_the_model_does_not_believe_loaded() -> None:
    policies = container_policies(load_model(default_model_path()), seed=0, makers=("hybrid", "highest"))
    scene = _tall_loaded_and_short_free()
    assert policies["highest"](scene) == "loaded"
    assert policies["hybrid"](scene) == "free"


@pytest.mark.slow  # physics runs of every decision maker
@pytest.mark.parametrize(
    "maker",
    [
        "hybrid_faces_veto",
        "hybrid_faces_free",
        "hybrid_faces_free_any",
        "hybrid_faces_free_8",
        "hybrid_faces_free_sure",
        "hybrid_faces_free_net",
        "hybrid_faces_free_gated",
        "hybrid_moves_free",
        "hybrid_moves_free_1",
        "hybrid_moves_walk",
        "hybrid_faces_walk",
    ],
)
def test_the_hybrid_vetoes_start_from_the_hybrids_pick_not_the_highest_box(maker: str) -> None:
    policies = container_policies(load_model(default_model_path()), seed=0, makers=(maker,))
    assert policies[maker](_tall_loaded_and_short_free()) == "free"  # its removal moves nothing


@pytest.mark.slow  # physics runs of every decision maker
def test_the_strict_default_takes_the_highest_box_below_the_strict_free_cost(small_dataset: Path) -> None:
    from unstack.experiments.container import CONTAINER_SAMPLES, STRICT_FREE_COST
    from unstack.pipeline import scene_support_probabilities
    from unstack.reasoner.decision import decide
    from unstack.scene import load_scene

    model = load_model(default_model_path())
    policies = container_policies(model, seed=0, makers=("unstack_strict",))
    for path in sorted(small_dataset.glob("config-*.json"))[:3]:
        scene = load_scene(path)
        decision = decide(scene_support_probabilities(scene, model), cost="load", samples=CONTAINER_SAMPLES, seed=0)
        costs = dict(zip(decision.objects, decision.expected_costs, strict=True))
        free = [box for box in scene.detected if costs[box] < STRICT_FREE_COST]
        pick = policies["unstack_strict"](scene)
        if free:
            assert pick == max(free, key=lambda box: (scene.box(box).position[2], box))
        else:
            assert pick == decision.choice


@pytest.mark.slow  # physics runs of every decision maker
def test_unstack_gives_near_ties_to_the_box_resting_highest_and_min_cost_keeps_eq13() -> None:
    boxes = [
        Box("a_low", [0.4, 0.4, 0.3], [1.2, -0.35, 0.151]),
        Box("base", [0.4, 0.4, 0.3], [1.2, 0.35, 0.151]),
        Box("b_high", [0.4, 0.4, 0.3], [1.2, 0.35, 0.452]),
    ]
    scene = Scene(boxes, surface_cloud(boxes, viewpoint=[-2.0, 0.0, 1.5], seed=0), ["a_low", "base", "b_high"])
    policies = container_policies(load_model(default_model_path()), seed=0, makers=("unstack", "min_cost"))
    assert policies["unstack"](scene) == "b_high"  # two free boxes: the one resting higher
    assert policies["min_cost"](scene) == "a_low"  # Eq. 12: the lower expected cost (or the smaller id)


@pytest.mark.slow  # physics runs of every decision maker
def test_unstack_never_takes_a_box_under_load() -> None:
    policies = container_policies(load_model(default_model_path()), seed=0, makers=("unstack",))
    assert policies["unstack"](_tall_loaded_and_short_free()) == "free"


@pytest.mark.slow  # physics runs of every decision maker
def test_containers_run_on_a_dask_cluster_with_the_same_results(small_dataset: Path) -> None:
    from distributed import LocalCluster

    from unstack.sim.dataset import scheduler_client

    model = load_model(default_model_path())
    options = {"piles": 1, "makers": ("unstack", "highest"), "max_picks": 2, "samples": 64}
    local = container_experiment(small_dataset, model, **options)  # type: ignore[arg-type]
    with (
        LocalCluster(n_workers=1, threads_per_worker=1, processes=True, dashboard_address=None) as cluster,
        scheduler_client(cluster.scheduler_address) as client,  # the command line's client: not the default one
    ):
        remote = container_experiment(small_dataset, model, client=client, **options)  # type: ignore[arg-type]
    assert remote["runs"] == local["runs"]


@pytest.mark.slow  # physics runs of every decision maker
def test_an_unreachable_scheduler_is_one_line(small_dataset: Path, tmp_path: Path) -> None:
    result = unstack("experiment", "container", str(small_dataset), "--out", str(tmp_path), "--scheduler", "nonsense")
    assert_one_line_error(result, "tcp://HOST:PORT")


def test_the_oracles_and_the_makers_measured_no_better_run_only_when_named() -> None:
    from unstack.experiments.container import DEFAULT_CONTAINER_MAKERS, ORACLE_MAKERS, TRIED_MAKERS

    opt_in = set(ORACLE_MAKERS) | set(TRIED_MAKERS)
    assert opt_in <= set(CONTAINER_MAKERS) and not opt_in & set(DEFAULT_CONTAINER_MAKERS)
    assert set(DEFAULT_CONTAINER_MAKERS) | opt_in == set(CONTAINER_MAKERS)
