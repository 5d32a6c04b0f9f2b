"""Data sets: manifest, resume after kill -9, refusal to mix, workers and dask give the same bytes."""

from __future__ import annotations

import hashlib
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from tests.sim.conftest import small_settings
from unstack.dataset_folders import list_configurations, read_manifest
from unstack.errors import UnstackError
from unstack.scene import load_scene
from unstack.sim.dataset import DatasetConflict, SchedulerUnavailable, simulate_dataset
from unstack.sim.settings import SimulationSettings

pytestmark = pytest.mark.slow  # simulates data sets


def digests(folder: Path) -> dict[str, str]:
    """SHA-256 of every configuration file (scene JSON and arrays)."""
    return {
        path.name: hashlib.sha256(path.read_bytes()).hexdigest()
        for path in sorted(folder.glob("config-*"))
        if not path.name.startswith(".")
    }


@pytest.fixture(scope="module")
def reference(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("reference")
    simulate_dataset(folder, small_settings(), configs=4, seed=21)
    return folder


def test_a_data_set_folder(reference: Path) -> None:
    manifest = read_manifest(reference)
    assert manifest is not None and manifest["format"] == "unstack.dataset/1"
    assert manifest["seed"] == 21 and manifest["configs"] == 4
    assert SimulationSettings.from_dict(manifest["settings"]) == small_settings()
    statistics = manifest["statistics"]
    assert statistics["configurations"] == 4
    assert 0.0 <= statistics["transitivity_violated_share"] <= 1.0
    scenes = [load_scene(path) for path in list_configurations(reference)]
    assert len(scenes) == 4 and all(scene.ground_truth is not None for scene in scenes)
    assert statistics["support_relations"] == sum(int(scene.ground_truth.sum()) for scene in scenes)  # type: ignore[union-attr]
    timings = [json.loads(line) for line in (reference / "timings.jsonl").read_text().splitlines()]
    assert sorted(t["index"] for t in timings) == [0, 1, 2, 3]


def test_rerunning_skips_finished_configurations(reference: Path, tmp_path: Path) -> None:
    simulate_dataset(tmp_path, small_settings(), configs=2, seed=21)
    summary = simulate_dataset(tmp_path, small_settings(), configs=4, seed=21)
    assert (summary.skipped, summary.made, summary.finished) == (2, 2, 4)
    assert digests(tmp_path) == digests(reference)
    again = simulate_dataset(tmp_path, small_settings(), configs=4, seed=21)
    assert again.made == 0


def test_two_workers_give_the_same_bytes(reference: Path, tmp_path: Path) -> None:
    simulate_dataset(tmp_path, small_settings(), configs=4, seed=21, jobs=2)
    assert digests(tmp_path) == digests(reference)


def test_a_dask_cluster_gives_the_same_bytes(reference: Path, tmp_path: Path) -> None:
    from distributed import LocalCluster

    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        simulate_dataset(tmp_path, small_settings(), configs=4, seed=21, scheduler=cluster.scheduler_address)
    assert digests(tmp_path) == digests(reference)


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"seed": 22}, r"manifest.json: \$.seed: the folder holds another data set \(seed 21, asked for 22\)"),
        (
            {"settings": small_settings(boxes=(3, 6))},
            r"\$.settings: the folder holds another data set \(settings differ in boxes\)",
        ),
    ],
)
def test_a_folder_of_another_data_set_is_refused(tmp_path: Path, change: dict[str, object], message: str) -> None:
    simulate_dataset(tmp_path, small_settings(), configs=1, seed=21)
    arguments: dict[str, object] = {"settings": small_settings(), "seed": 21, **change}
    with pytest.raises(DatasetConflict, match=message):
        simulate_dataset(tmp_path, arguments["settings"], configs=2, seed=arguments["seed"])  # type: ignore[arg-type]
    assert len(list_configurations(tmp_path)) == 1


def test_a_data_set_of_one_box_piles_is_refused_by_the_settings_name(tmp_path: Path) -> None:
    with pytest.raises(UnstackError, match=r"^settings\.boxes: 1-4: a pile of one box supports nothing"):
        simulate_dataset(tmp_path, small_settings(boxes=(1, 4)), configs=1, seed=21)
    assert not any(tmp_path.iterdir())


@pytest.mark.parametrize("content", ["{not json", '{"format": "unstack.scene/1"}'], ids=["garbage", "foreign"])
def test_configurations_without_a_manifest_are_no_data_set_to_add_to(tmp_path: Path, content: str) -> None:
    """A run writes its manifest first: configurations without one are another's (they were taken as finished)."""
    (tmp_path / "config-0000.json").write_text(content)
    with pytest.raises(
        DatasetConflict, match=r"holds 1 configuration file\(s\) \(config-0000.json, ...\) and no manifest"
    ):
        simulate_dataset(tmp_path, small_settings(), configs=2, seed=21)
    assert sorted(path.name for path in tmp_path.iterdir()) == ["config-0000.json"]


def test_a_folder_holding_only_the_manifest_of_a_stopped_run_takes_another_data_set(
    reference: Path, tmp_path: Path
) -> None:
    simulate_dataset(tmp_path, small_settings(boxes=(3, 6)), configs=1, seed=22)
    for path in tmp_path.glob("config-*"):  # as a run stopped before its first configuration leaves it
        path.unlink()
    (tmp_path / "timings.jsonl").unlink()
    summary = simulate_dataset(tmp_path, small_settings(), configs=4, seed=21)
    manifest = read_manifest(tmp_path)
    assert summary.made == 4 and manifest is not None and (manifest["seed"], manifest["configs"]) == (21, 4)
    assert SimulationSettings.from_dict(manifest["settings"]) == small_settings()
    assert digests(tmp_path) == digests(reference)


def test_a_scheduler_that_does_not_answer_fails_fast(tmp_path: Path) -> None:
    start = time.monotonic()
    with pytest.raises(SchedulerUnavailable, match=r"dask scheduler tcp://127.0.0.1:9 does not answer within 5 s"):
        simulate_dataset(tmp_path / "out", small_settings(), configs=1, seed=0, scheduler="tcp://127.0.0.1:9")
    assert time.monotonic() - start < 30
    assert not (tmp_path / "out").exists()


def test_kill_minus_nine_loses_only_configurations_in_flight(tmp_path: Path) -> None:
    folder = tmp_path / "killed"
    command = [sys.executable, "-m", "unstack", "simulate", "--configs", "12", "--boxes", "6-8", "--sizes", "four",
               "--depth", "1.0", "--resolution", "96x72", "--min-pixels", "5", "--horizon", "0.5", "--seed", "3",
               "--out", str(folder), "--jobs", "2"]  # fmt: skip
    process = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
    deadline = time.monotonic() + 120
    while len(list_configurations(folder)) < 2 and time.monotonic() < deadline and process.poll() is None:
        time.sleep(0.05)
    os.killpg(process.pid, signal.SIGKILL)
    process.wait()
    finished = list_configurations(folder)
    assert 0 < len(finished) < 12, "the kill must land while configurations are in flight"
    for scene_file in finished:  # every finished scene is whole, with its arrays
        load_scene(scene_file)
    visible = [path for path in folder.iterdir() if not path.name.startswith(".")]
    stems = {path.name.split(".")[0] for path in visible if path.name.startswith("config-")}
    assert all((folder / f"{stem}.json").exists() or (folder / f"{stem}.point_boxes.npy").exists() for stem in stems)
    subprocess.run(command, check=True, capture_output=True)
    assert not [path for path in folder.iterdir() if path.name.startswith(".")]
    uninterrupted = tmp_path / "whole"
    subprocess.run([*command[:-3], str(uninterrupted), "--jobs", "1"], check=True, capture_output=True)
    assert digests(folder) == digests(uninterrupted)


def test_a_second_run_on_a_folder_being_written_is_refused(tmp_path: Path) -> None:
    from unstack.atomic import folder_writer

    with (
        folder_writer(tmp_path, "a data set"),
        pytest.raises(
            DatasetConflict, match=rf"another unstack run \(pid {os.getpid()}\) is writing a data set in this folder"
        ),
    ):
        simulate_dataset(tmp_path, small_settings(), configs=1, seed=21)
    assert list_configurations(tmp_path) == [] and read_manifest(tmp_path) is None
