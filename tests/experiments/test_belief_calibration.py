"""Physics on the belief against the true pile, candidate by candidate."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from tests.conftest import unstack
from unstack.experiments.belief_calibration import belief_calibration, pick_summary

pytestmark = pytest.mark.slow  # physics: the true pile and the belief, every candidate


@pytest.fixture(scope="module")
def result(small_dataset: Path) -> dict[str, object]:
    return belief_calibration(small_dataset, piles=2, worlds=1, max_picks=2, seed=1)


def test_every_state_compares_every_rule(result: dict[str, object]) -> None:
    picks = result["picks"]
    assert picks["states"] == 4  # type: ignore[index]
    assert picks["lookahead"] <= min(picks["highest"], picks["belief"])  # type: ignore[index]
    assert sum(row["states"] for row in result["per_pile"]) == 4  # type: ignore[attr-defined, union-attr]


def test_the_calibration_bins_hold_every_candidate(result: dict[str, object]) -> None:
    calibration = result["calibration"]
    assert sum(row["picks"] for row in calibration["bins"]) == calibration["picks"] > 4  # type: ignore[index]


def test_the_summary_sums_each_rule() -> None:
    states = [
        {"highest": 3, "belief": 1, "belief_veto": 2, "lookahead": 0},
        {"highest": 1, "belief": 1, "belief_veto": 1, "lookahead": 1},
    ]
    assert pick_summary(states) == {"states": 2, "highest": 4, "belief": 2, "belief_veto": 3, "lookahead": 1}


def test_the_cli_writes_the_report(small_dataset: Path, tmp_path: Path) -> None:
    out = tmp_path / "calibration"
    run = unstack("experiment", "belief-calibration", str(small_dataset), "--out", str(out), "--piles", "1",
                  "--max-picks", "1", "--worlds", "1")  # fmt: skip
    assert run.returncode == 0, run.stderr
    assert "Spearman's rank correlation" in run.stdout
    assert json.loads((out / "belief-calibration.json").read_text())["picks"]["states"] == 1


def test_a_folder_without_piles_is_one_line(tmp_path: Path) -> None:
    run = unstack("experiment", "belief-calibration", str(tmp_path), "--out", str(tmp_path / "out"))
    assert run.returncode == 2 and "Traceback" not in run.stderr and len(run.stderr.strip().splitlines()) == 1
