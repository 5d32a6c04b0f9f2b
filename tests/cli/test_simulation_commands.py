"""``unstack simulate`` and ``unstack render`` as a user runs them."""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.conftest import assert_one_line_error, unstack

pytestmark = pytest.mark.slow  # simulates piles in subprocesses

SMALL = ["--boxes", "3-4", "--sizes", "four", "--depth", "1.0", "--resolution", "96x72", "--min-pixels", "5",
         "--horizon", "0.5"]  # fmt: skip


@pytest.fixture(scope="module")
def dataset(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("cli") / "data"
    result = unstack("simulate", "--configs", "2", *SMALL, "--seed", "4", "--out", str(folder))
    assert result.returncode == 0, result.stderr
    assert "2 configurations (2 made, 0 already there)" in result.stdout
    assert "do not label x supporting z" in result.stdout
    return folder


def test_simulate_writes_scene_files_that_validate(dataset: Path) -> None:
    files = sorted(str(path) for path in dataset.glob("config-*.json"))
    result = unstack("validate", str(dataset / "manifest.json"), *files)
    assert result.returncode == 0, result.stderr
    assert "valid unstack.dataset/1 (2 configurations, seed 4)" in result.stdout
    assert result.stdout.count("valid unstack.scene/1") == 2


def test_render_writes_a_png(dataset: Path, tmp_path: Path) -> None:
    target = tmp_path / "pile.png"
    result = unstack("render", str(dataset / "config-0000.json"), "-o", str(target))
    assert result.returncode == 0, result.stderr
    assert target.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert [path.name for path in tmp_path.iterdir()] == ["pile.png"]


def test_simulate_a_staged_family_of_boxes_set_down_by_hand(tmp_path: Path) -> None:
    import json

    folder = tmp_path / "staged"
    result = unstack("simulate", "--family", "staged", "--configs", "1", "--resolution", "96x72", "--min-pixels", "5",
                     "--horizon", "0.5", "--seed", "2", "--out", str(folder))  # fmt: skip
    assert result.returncode == 0, result.stderr
    settings = json.loads((folder / "manifest.json").read_text())["settings"]
    assert settings["pile"]["arrangement"] == "structures" and settings["sizes"] == "cartons"
    assert unstack("validate", str(folder / "config-0000.json")).returncode == 0


def test_simulate_refuses_to_mix_data_sets(dataset: Path) -> None:
    result = unstack("simulate", "--configs", "2", *SMALL, "--seed", "5", "--out", str(dataset))
    assert result.returncode == 2
    assert "the folder holds another data set (seed 4, asked for 5)" in result.stderr


@pytest.mark.parametrize(
    ("arguments", "message"),
    [
        (["examples/scene3.json", "-o", "{tmp}/x.pdf"], "x.pdf: expected a .png or .svg output file"),
        (["examples/missing.json", "-o", "{tmp}/x.png"], "missing.json"),
    ],
)
def test_render_bad_input_is_one_line(tmp_path: Path, arguments: list[str], message: str) -> None:
    result = unstack("render", *[argument.format(tmp=tmp_path) for argument in arguments])
    assert_one_line_error(result, message, nothing_written_in=tmp_path)


def test_render_draws_the_learned_probabilities(tmp_path: Path) -> None:
    plain, arrows = tmp_path / "plain.png", tmp_path / "arrows.png"
    assert unstack("render", "examples/pile5.scene.json", "-o", str(plain)).returncode == 0
    result = unstack("render", "examples/pile5.scene.json", "-o", str(arrows), "--probabilities")
    assert result.returncode == 0, result.stderr
    assert arrows.read_bytes()[:4] == b"\x89PNG" and arrows.read_bytes() != plain.read_bytes()


@pytest.mark.parametrize("ending, code", [("SIGINT", 130), ("SIGTERM", 143)])
def test_ctrl_c_or_sigterm_ends_a_run_with_one_line_and_the_shells_exit_code(
    tmp_path: Path, ending: str, code: int
) -> None:
    import signal
    import subprocess
    import sys
    import time

    folder = tmp_path / "interrupted"
    command = [sys.executable, "-m", "unstack", "simulate", "--configs", "50", *SMALL, "--out", str(folder)]

    def as_from_a_shell() -> None:  # a test runner's worker may ignore SIGINT, and a child inherits that
        signal.signal(signal.SIGINT, signal.SIG_DFL)

    process = subprocess.Popen(
        command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, preexec_fn=as_from_a_shell
    )
    deadline = time.monotonic() + 120
    while not (folder / "config-0000.json").exists() and time.monotonic() < deadline and process.poll() is None:
        time.sleep(0.05)
    process.send_signal(getattr(signal, ending))
    _, stderr = process.communicate(timeout=120)
    assert process.returncode == code, stderr
    assert stderr.strip().splitlines()[-1] == "unstack: aborted"
    assert not (folder / ".unstack-writer.lock").exists()  # the run unwound: its lock is gone
