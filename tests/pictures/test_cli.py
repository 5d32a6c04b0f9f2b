"""``unstack render`` and ``unstack view`` as a user runs them."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from tests.conftest import assert_one_line_error, unstack

pytestmark = pytest.mark.slow  # renders pictures through the CLI in subprocesses

PILE5 = "examples/pile5.scene.json"


def test_render_shows_the_decision_in_png_and_svg(tmp_path: Path) -> None:
    png, svg = tmp_path / "pile.png", tmp_path / "pile.svg"
    result = unstack("render", PILE5, "-o", str(png), "--plan", "--probabilities", "--threshold", "0.3")
    assert result.returncode == 0, result.stderr
    assert result.stdout.startswith(f"{png}: 37 boxes, 5 detected; pick ")
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert unstack("render", PILE5, "-o", str(svg)).returncode == 0
    assert svg.read_text().lstrip().startswith("<?xml")


def test_render_a_stored_decision_and_a_supports_file(tmp_path: Path) -> None:
    decision = tmp_path / "decision.json"
    assert unstack("decide", PILE5, "--json", "-o", str(decision)).returncode == 0
    choice = json.loads(decision.read_text())["choice"]
    result = unstack("render", PILE5, "--decision", str(decision), "-o", str(tmp_path / "stored.png"))
    assert result.returncode == 0, result.stderr
    assert result.stdout.rstrip().endswith(f"pick {choice}")
    graph = unstack("render", "examples/pile31.supports.json", "-o", str(tmp_path / "graph.png"))
    assert graph.returncode == 0, graph.stderr
    assert "support graph of 31 boxes" in graph.stdout


def test_render_colours_by_ground_truth_without_a_model(tmp_path: Path) -> None:
    result = unstack("render", PILE5, "-o", str(tmp_path / "truth.png"), "--colour", "truth")
    assert result.returncode == 0, result.stderr
    assert "pick" not in result.stdout


@pytest.fixture(scope="module")
def every_box_decision(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A decision on pile5's boxes with every box detected, not only the five the scene detects."""
    folder = tmp_path_factory.mktemp("every")
    document = json.loads(Path(PILE5).read_text())
    document["detected"] = [box["id"] for box in document["boxes"]]
    document["points_file"] = str((Path(PILE5).parent / document["points_file"]).resolve())
    (folder / "every.json").write_text(json.dumps(document))
    decision = folder / "decision.json"
    assert unstack("decide", str(folder / "every.json"), "--json", "-o", str(decision)).returncode == 0
    return decision


@pytest.fixture(scope="module")
def other_decision(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A decision about other boxes (pile7's) than pile5's."""
    decision = tmp_path_factory.mktemp("other") / "decision.json"
    assert unstack("decide", "examples/pile7.supports.json", "--json", "-o", str(decision)).returncode == 0
    return decision


@pytest.mark.parametrize(
    ("arguments", "message"),
    [
        (["render", "examples/missing.json", "-o", "{tmp}/x.png"], "missing.json: $: no such file"),
        (["render", PILE5, "-o", "{tmp}/x.pdf"], "x.pdf: expected a .png or .svg output file"),
        (["render", PILE5, "-o", "{tmp}/x.png", "--threshold", "1.5"], "threshold must be a probability in [0, 1]"),
        (["render", PILE5, "-o", "{tmp}/x.png", "--decision", "{decision}"], "the decision's boxes do not match"),
        (["render", PILE5, "-o", "{tmp}/x.png", "--decision", "{wider}"], "the decision's boxes are not the boxes"),
        (["render", PILE5, "-o", "{tmp}/x.png", "--decision", "{wider}", "--model", "paper"], "--model decides with"),
        (["render", PILE5, "-o", "{tmp}/x.png", "--decision", "examples/stack5.supports.json"], "unstack.decision/1"),
        (["render", PILE5, "-o", "{tmp}/no/x.png"], "cannot write there"),
        (["render", "examples/pile31.supports.json", "-o", "{tmp}/x.png", "--colour", "truth"], "no ground truth"),
        (["view", "examples/pile31.supports.json", "-o", "{tmp}/x.html"], "no geometry to show in 3D"),
        (["view", PILE5, "-o", "{tmp}/x.png"], "x.png: expected a .html or .htm output file"),
        (["view", PILE5, "-o", "{tmp}/x.html", "--max-points", "-1"], "--max-points"),
        (["view", PILE5, "-o", "{tmp}/x.html", "--max-points", "5000000"], "5000000 is not in the range 0<=x<=1000000"),
        (["view", "nothing.json", "-o", "{tmp}/x.html"], "nothing.json: $: no such file"),
    ],
)
def test_bad_picture_input_is_one_line(
    tmp_path: Path, other_decision: Path, every_box_decision: Path, arguments: list[str], message: str
) -> None:
    result = unstack(*[a.format(tmp=tmp_path, decision=other_decision, wider=every_box_decision) for a in arguments])
    assert_one_line_error(result, message, nothing_written_in=tmp_path)
    assert result.stderr.startswith("unstack: error: "), result.stderr


def test_view_writes_one_self_contained_page(tmp_path: Path) -> None:
    target = tmp_path / "pile.html"
    result = unstack("view", PILE5, "-o", str(target), "--plan", "--max-points", "3000")
    assert result.returncode == 0, result.stderr
    assert " MB" in result.stdout and "pick " in result.stdout
    page = target.read_text()
    assert "picks taken: " in page and "cloud (3,000 of " in page
