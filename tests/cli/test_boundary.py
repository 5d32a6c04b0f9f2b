"""Bad input at the command line: one line on stderr, exit code 2, never a traceback or a hang."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from tests.conftest import PILE5, assert_one_line_error, unstack

pytestmark = pytest.mark.slow  # runs the CLI in subprocesses

REPO = Path(__file__).resolve().parents[2]


def one_line_error(result: subprocess.CompletedProcess[str], *fragments: str) -> None:
    assert result.returncode == 2, (result.returncode, result.stderr)
    assert result.stderr.startswith("unstack: error: ") and result.stderr.count("\n") == 1, result.stderr
    assert "Traceback" not in result.stderr
    for fragment in fragments:
        assert fragment in result.stderr, result.stderr


@pytest.fixture
def contradiction(tmp_path: Path) -> Path:
    """A supports file in which a surely supports b and b surely c, but a surely not c: no consistent world."""
    path = tmp_path / "contradiction.json"
    cycle = {
        "format": "unstack.supports/1",
        "objects": ["a", "b", "c"],
        "probabilities": [[0, 1, 0], [0, 0, 1], [0, 0, 0]],
    }
    path.write_text(json.dumps(cycle))
    return path


def test_closed_standard_input() -> None:
    result = subprocess.run(
        f"{sys.executable} -m unstack decide - <&-", shell=True, capture_output=True, text=True, cwd=REPO, timeout=120
    )
    one_line_error(result, "<stdin>: $: standard input is closed")


def test_deeply_nested_json(tmp_path: Path) -> None:
    deep = tmp_path / "deep.json"
    deep.write_text('{"format": ' + "[" * 100_000 + "]" * 100_000 + "}")
    one_line_error(unstack("decide", str(deep)), f"{deep}: $", "nested at most 64 levels")


def test_a_huge_integer(tmp_path: Path) -> None:
    huge = tmp_path / "huge.json"
    huge.write_text('{"format": "unstack.supports/1", "objects": ["a"], "probabilities": [[' + "9" * 5000 + "]]}")
    one_line_error(unstack("decide", str(huge)), f"{huge}: $: invalid JSON")


def test_a_box_far_away(tmp_path: Path, examples: Path) -> None:
    document = json.loads((examples / "scene3.json").read_text())
    document["boxes"][0]["position"] = [1e300, 0.0, 0.0]
    (tmp_path / "scene3.points.npy").write_bytes((examples / "scene3.points.npy").read_bytes())
    far = tmp_path / "far.json"
    far.write_text(json.dumps(document))
    one_line_error(unstack("decide", str(far)), f"{far}: $.boxes[0].position[0]")


def test_a_text_file_named_npy(tmp_path: Path, examples: Path) -> None:
    document = json.loads((examples / "scene3.json").read_text())
    (tmp_path / "scene3.points.npy").write_text("x y z\n0 0 0\n")
    scene = tmp_path / "scene.json"
    scene.write_text(json.dumps(document))
    result = unstack("decide", str(scene))
    one_line_error(result, f"{scene}: $.points_file")
    assert "pickle" not in result.stderr


def test_model_on_a_supports_file_is_an_error() -> None:
    one_line_error(unstack("decide", PILE5, "--model", "paper"), PILE5, "--model applies to a scene file")
    one_line_error(unstack("plan", PILE5, "--model", "extended"), "--model applies to a scene file")


def test_ids_with_control_characters_are_escaped(tmp_path: Path) -> None:
    file = tmp_path / "escape.json"
    objects = ["top\x1b[31m", "bottom\x07[bold]"]
    file.write_text(
        json.dumps({"format": "unstack.supports/1", "objects": objects, "probabilities": [[0, 0.1], [0.9, 0]]})
    )
    for command in ("decide", "plan", "worlds", "validate"):
        result = unstack(command, str(file))
        assert result.returncode == 0, result.stderr
        assert "\x1b" not in result.stdout and "\x07" not in result.stdout, command
        if command != "validate":
            assert "top\\x1b[31m" in result.stdout, (command, result.stdout)
    assert json.loads(unstack("decide", str(file), "--json").stdout)["choice"] == objects[0]
    duplicate = tmp_path / "duplicate.json"
    duplicate.write_text(
        json.dumps({"format": "unstack.supports/1", "objects": ["\x1b", "\x1b"], "probabilities": [[0, 0], [0, 0]]})
    )
    result = unstack("decide", str(duplicate))
    one_line_error(result, "appears twice")
    assert "\x1b" not in result.stderr


def test_an_output_in_a_missing_folder_fails_before_any_work(tmp_path: Path) -> None:
    rng = np.random.default_rng(0)
    p = rng.uniform(0.05, 0.95, (30, 30))
    np.fill_diagonal(p, 0.0)
    big = tmp_path / "big.json"
    big.write_text(
        json.dumps(
            {"format": "unstack.supports/1", "objects": [f"b{i}" for i in range(30)], "probabilities": p.tolist()}
        )
    )
    target = tmp_path / "missing" / "out.json"
    for command in ("decide", "plan"):  # the most sweeps accepted: only failing first returns in time
        result = unstack(command, str(big), "--samples", "100000000", "--output", str(target))
        one_line_error(result, f"{target}: cannot write there: the folder {target.parent} does not exist")
    assert not target.parent.exists()


def test_validate_checks_every_file_and_summarises(tmp_path: Path, contradiction: Path) -> None:
    missing = tmp_path / "missing.json"
    result = unstack("validate", str(missing), PILE5, str(contradiction), "examples/scene3.json")
    assert result.returncode == 2
    errors = result.stderr.splitlines()
    assert len(errors) == 2 and all(line.startswith("unstack: error: ") for line in errors)
    assert f"{missing}: $: no such file" in errors[0]
    assert f"{contradiction}: $.probabilities[0][2]: no consistent world" in errors[1]
    assert f"{PILE5}: valid unstack.supports/1" in result.stdout
    assert result.stdout.splitlines()[-1] == "4 files: 2 valid, 2 invalid"
    good = unstack("validate", PILE5)
    assert good.returncode == 0 and good.stdout.splitlines()[-1] == "1 file: 1 valid, 0 invalid"


def test_a_contradiction_in_decide_names_the_file(contradiction: Path) -> None:
    one_line_error(
        unstack("decide", str(contradiction)), f"{contradiction}: $.probabilities[0][2]: no consistent world"
    )


def test_warnings_in_the_supports_metadata_are_printed(tmp_path: Path) -> None:
    file = tmp_path / "warned.json"
    file.write_text(
        json.dumps(
            {
                "format": "unstack.supports/1",
                "objects": ["a", "b"],
                "probabilities": [[0, 0.1], [0.9, 0]],
                "metadata": {"warnings": ["box a floats above box b", "the cloud is\x1b sparse"]},
            }
        )
    )
    result = unstack("decide", str(file), "--json")
    assert result.returncode == 0
    assert result.stderr.splitlines() == [
        "unstack: warning: box a floats above box b",
        "unstack: warning: the cloud is\\x1b sparse",
    ]
    assert json.loads(result.stdout)["warnings"] == ["box a floats above box b", "the cloud is\x1b sparse"]


def test_timing_only_on_request() -> None:
    plain = json.loads(unstack("decide", PILE5, "--json").stdout)
    timed = json.loads(unstack("decide", PILE5, "--json", "--timing").stdout)
    assert "timing" not in plain and timed.pop("timing")["seconds"] >= 0
    assert plain == timed


def test_warm_up_reports_each_kernel() -> None:
    result = unstack("warm-up", "--jobs", "2")
    assert result.returncode == 0, result.stderr
    lines = result.stderr.splitlines()
    assert lines[0].startswith("warm-up: compiling 4 groups of kernels in 2 processes")
    assert [line.split("] ")[0] for line in lines[1:]] == [f"warm-up: [{k}/4" for k in range(1, 5)]
    assert sorted(line.split("] ")[1].split(" ready")[0] for line in lines[1:]) == [
        "exact engine",
        "feature kernels",
        "sampler",
        "wide sampler",
    ]
    assert result.stdout.startswith("warm-up: done in ")


def test_standard_input_that_is_not_utf8_is_refused_like_a_file(examples: Path) -> None:
    document = (examples / "stack5.supports.json").read_text().replace('"top_left"', '"caf\u00e9"', 1)
    result = subprocess.run(
        [sys.executable, "-m", "unstack", "decide", "-"],
        input=document.encode("latin-1"),
        capture_output=True,
        cwd=REPO,
        timeout=120,
    )
    text = subprocess.CompletedProcess(result.args, result.returncode, result.stdout.decode(), result.stderr.decode())
    one_line_error(text, "<stdin>: $: cannot read standard input: 'utf-8' codec can't decode")


def test_an_unknown_model_name_lists_the_shipped_ones(examples: Path) -> None:
    result = unstack("decide", str(examples / "pile5.scene.json"), "--model", "nosuchmodel")
    one_line_error(
        result, "nosuchmodel: $: no shipped model and no file of that name (shipped: general, paper, extended)"
    )


def test_an_output_the_system_refuses_names_the_output_not_a_temporary_file() -> None:
    target = Path("/proc/unstack-decision.json")
    result = unstack("decide", PILE5, "--output", str(target))
    one_line_error(result, f"{target}: cannot write there:")
    assert ".tmp" not in result.stderr


def test_validate_and_render_warn_about_a_box_in_the_floor_as_decide_does(tmp_path: Path, examples: Path) -> None:
    document = json.loads((examples / "scene3.json").read_text())
    document["boxes"][0]["position"][2] = 0.05  # 0.15 m of a 0.4 m box below z = 0
    document["points_file"] = str(examples / document["points_file"])
    sunk = tmp_path / "sunk.json"
    sunk.write_text(json.dumps(document))
    expected = f"unstack: warning: {sunk}: box 'floor_a' reaches 0.15 m into the floor (z = 0)"
    validated = unstack("validate", str(sunk))
    assert validated.returncode == 0 and "1 valid, 0 invalid" in validated.stdout
    rendered = unstack("render", str(sunk), "-o", str(tmp_path / "sunk.png"), "--colour", "none")
    assert rendered.returncode == 0, rendered.stderr
    decided = unstack("decide", str(sunk))
    for result in (validated, rendered, decided):
        assert expected in result.stderr, result.stderr


def test_chains_that_have_not_mixed_are_warned_about_once_on_stderr_and_in_the_json() -> None:
    text = unstack("decide", "examples/pile31.supports.json", "--samples", "500", "--seed", "0")
    assert text.returncode == 0, text.stderr
    assert text.stderr.count("the chains disagree") == 1 and "chains disagree" not in text.stdout
    as_json = unstack("decide", "examples/pile31.supports.json", "--samples", "500", "--seed", "0", "--json")
    document = json.loads(as_json.stdout)
    assert document["sampling"]["warning"] in document["warnings"]
    assert as_json.stderr.startswith("unstack: warning: the chains disagree")


@pytest.mark.parametrize(
    ("command", "setting", "value", "fragment"),
    [
        (["decide", "--physics-veto"], "pile", "x", "$.metadata.settings.pile: expected an object, got 'x'"),
        (["decide", "--physics-veto"], "ground_truth", {"horizon": 1e6}, "$.metadata.settings.ground_truth.horizon"),
        (["validate"], "sensor", {"width": "wide"}, "$.metadata.settings.sensor.width: expected a whole number"),
        (["render", "--output", "PICTURE"], "sensor", {"position": [0, 0]}, "$.metadata.settings.sensor.position"),
    ],
)
def test_simulation_settings_of_a_scene_are_checked_where_they_are_read(
    tmp_path: Path, examples: Path, command: list[str], setting: str, value: object, fragment: str
) -> None:
    scene = json.loads((examples / "pile5.scene.json").read_text())
    scene["metadata"]["settings"][setting] = value
    (tmp_path / "pile5.scene.points.npy").write_bytes((examples / "pile5.scene.points.npy").read_bytes())
    path = tmp_path / "pile5.scene.json"
    path.write_text(json.dumps(scene))
    arguments = [str(tmp_path / "out.png") if part == "PICTURE" else part for part in command]
    one_line_error(unstack(*arguments, str(path)), str(path), fragment)
    assert not (tmp_path / "out.png").exists()


def test_validate_checks_the_settings_of_a_data_set_manifest(tmp_path: Path) -> None:
    from unstack.sim.settings import SimulationSettings

    settings = SimulationSettings().to_dict()
    settings["pile"]["mass_range"] = [15.0, 5.0]
    manifest = {"format": "unstack.dataset/1", "seed": 0, "configs": 1, "settings": settings}
    path = tmp_path / "manifest.json"
    path.write_text(json.dumps(manifest))
    one_line_error(unstack("validate", str(path)), "$.settings.pile.mass_range: expected [low, high] with low <= high")


@pytest.mark.parametrize(
    ("option", "value", "fragment"),
    [
        ("--depth", "nan", "Invalid value for '--depth': expected a finite number, got nan"),
        ("--width", "1e12", "Invalid value for '--width': expected a positive extent of at most 100 m"),
        ("--horizon", "inf", "Invalid value for '--horizon': expected a finite number, got inf"),
        ("--horizon", "1e12", "Invalid value for '--horizon': expected a number from 0.001 to 10"),
        ("--min-pixels", "-1", "Invalid value for '--min-pixels': expected a number at least 1, got -1"),
        ("--viewpoint-jitter", "nan", "Invalid value for '--viewpoint-jitter': expected a finite number"),
        ("--resolution", "0x480", "--resolution: expected a number from 1 to 8192, got 0 in '0x480'"),
    ],
)
def test_simulate_refuses_a_setting_out_of_range_before_any_work(
    tmp_path: Path, option: str, value: str, fragment: str
) -> None:
    folder = tmp_path / "piles"
    one_line_error(unstack("simulate", "--configs", "1", "--out", str(folder), option, value), fragment)
    assert not folder.exists()


@pytest.mark.parametrize(
    ("command", "fragment"),
    [
        (["train", "DATA", "-o", "MODEL", "--offset", "inf"], "feature settings need 0 < offset <= 10 m, got inf"),
        (["train", "DATA", "-o", "MODEL", "--pose-noise", "nan"], "pose_noise must be a finite number, got nan"),
        (["evaluate", "general", "DATA", "--pose-noise", "nan"], "pose_noise must be a finite number, got nan"),
    ],
)
def test_learning_commands_refuse_lengths_that_are_not_finite(
    tmp_path: Path, small_dataset: Path, command: list[str], fragment: str
) -> None:
    model = tmp_path / "model.skops"
    arguments = [str(small_dataset) if part == "DATA" else str(model) if part == "MODEL" else part for part in command]
    one_line_error(unstack(*arguments), fragment)
    assert not model.exists()


@pytest.mark.parametrize("command", ["decide", "plan", "worlds", "probabilities"])
def test_an_output_on_the_input_file_is_refused_and_the_input_kept(tmp_path: Path, command: str) -> None:
    source = Path("examples/scene3.json" if command == "probabilities" else "examples/stack5.supports.json")
    given = tmp_path / source.name
    given.write_text(source.read_text())
    if command == "probabilities":
        (tmp_path / "scene3.points.npy").write_bytes(Path("examples/scene3.points.npy").read_bytes())
    result = unstack(command, str(given), "--output", str(tmp_path / "." / given.name))
    one_line_error(result, f"cannot write there: it is the input file {given}")
    assert given.read_text() == source.read_text()


@pytest.mark.parametrize(
    ("arguments", "message"),
    [
        (
            ["experiment", "container", "{data}", "--out", "{tmp}/r", "--makers", ","],
            "--makers: expected decision makers",
        ),
        (
            ["experiment", "container", "{data}", "--out", "{tmp}/r", "--disturbance", "examples/stack5.supports.json"],
            "stack5.supports.json: $: expected an unstack model file",
        ),
        (["experiment", "decisions", "{tmp}/no-data", "--out", "{tmp}/r"], "expected a data set folder"),
        (["experiment", "real7", "{data}", "--out", "{tmp}/a-file"], "{tmp}/a-file: expected a folder for the results"),
        (["experiment", "fig5a", "{data}", "--out", "{tmp}/a-file/r"], "but {tmp}/a-file is a file"),
        (["simulate", "--configs", "1", "--out", "{tmp}/a-file/d"], "but {tmp}/a-file is a file"),
        (["decide", PILE5, "-o", "-"], "-: expected a file name for the output"),
        (["render", "examples/scene3.json", "-o", "{tmp}/p.png", "--title", "T" * 201], "--title: expected one line"),
    ],
)
def test_an_experiment_refuses_before_any_work_and_leaves_no_folder(
    tmp_path: Path, small_dataset: Path, arguments: list[str], message: str
) -> None:
    (tmp_path / "a-file").write_text("")
    result = unstack(*[argument.format(tmp=tmp_path, data=small_dataset) for argument in arguments])
    one_line_error(result, message.format(tmp=tmp_path))
    assert sorted(path.name for path in tmp_path.iterdir()) == ["a-file"]


def test_a_run_with_standard_output_closed_fails_instead_of_losing_the_result() -> None:
    import os

    result = subprocess.run(
        [sys.executable, "-m", "unstack", "decide", PILE5, "--json"],
        stderr=subprocess.PIPE,
        text=True,
        cwd=REPO,
        preexec_fn=lambda: os.close(1),  # the child starts with no standard output
        timeout=120,
    )
    assert result.returncode == 2 and result.stderr == (
        "unstack: error: standard output is closed: nothing could be printed; redirect it to a file or to /dev/null\n"
    )


@pytest.mark.parametrize(
    "variable, value, message",
    [("NUMBA_NUM_THREADS", "0", "NUMBA_NUM_THREADS: expected a whole number of at least 1, got '0'"),
     ("NUMBA_NUM_THREADS", "abc", "NUMBA_NUM_THREADS: expected a whole number of at least 1, got 'abc'"),
     ("NUMBA_DISABLE_JIT", "1", "NUMBA_DISABLE_JIT is set: the reasoner's kernels need numba's compiler; unset it")],
)  # fmt: skip
def test_numba_settings_the_reasoner_cannot_run_with_are_one_line(variable: str, value: str, message: str) -> None:
    result = unstack("decide", "examples/pile31.supports.json", env={variable: value})
    assert_one_line_error(result, message)


def test_numbas_cache_without_a_writable_folder_is_one_line(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    from unstack.cli import main as cli_main

    def uncached(**_: object) -> None:  # what numba raises where no cache folder is writable
        raise RuntimeError("cannot cache function '_uniform': no locator available for file '/site/_sampler.py'")

    monkeypatch.setattr(cli_main.cli, "main", uncached)
    monkeypatch.setattr(cli_main.signal, "signal", lambda *_: None)  # the test process keeps its handlers
    with pytest.raises(SystemExit) as ended:
        cli_main.main()
    assert ended.value.code == 2
    assert capsys.readouterr().err.strip() == (
        "unstack: error: numba cannot cache its compiled kernels: neither the package's folder nor NUMBA_CACHE_DIR "
        "(or ~/.cache) is writable; set NUMBA_CACHE_DIR to a writable folder"
    )


def test_matplotlib_without_a_writable_folder_is_one_warning_line(tmp_path: Path) -> None:
    not_a_folder = tmp_path / "mplconfig"
    not_a_folder.write_text("")
    result = unstack(
        "render", "examples/pile5.scene.json", "-o", str(tmp_path / "p.png"), env={"MPLCONFIGDIR": str(not_a_folder)}
    )
    assert result.returncode == 0, result.stderr
    assert result.stderr.count("\n") == 1 and result.stderr.startswith(
        f"unstack: warning: matplotlib: MPLCONFIGDIR ({not_a_folder}) is not a writable folder; its cache is kept in "
    ), result.stderr
    assert result.stderr.endswith("for this run only (set MPLCONFIGDIR to a writable folder)\n")
