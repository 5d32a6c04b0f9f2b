"""The interactive page: self-contained, EC colours, hover text, the plan slider; seen in a real browser."""

from __future__ import annotations

import re
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

from unstack.errors import InvalidArgument
from unstack.pictures.values import DecisionValues
from unstack.pictures.view import build_view, hover_text, write_view
from unstack.scene import Scene

pytestmark = pytest.mark.slow  # writes plotly pages and opens one in headless Chromium


def test_the_page_holds_the_decision(wall: Scene, wall_decision: DecisionValues, rng: np.random.Generator) -> None:
    behind = np.column_stack([rng.uniform(1.45, 1.5, 2000), rng.uniform(-1, 1, 2000), rng.uniform(0.3, 1.4, 2000)])
    scene = Scene(wall.boxes, points=np.concatenate([wall.points, behind]), detected=wall.detected)
    figure = build_view(scene, values=wall_decision, max_points=500, seed=1)
    cloud = figure.data[0]
    assert len(cloud.x) == 500 and min(cloud.x) >= 1.45  # subsampled; points on detected boxes left out
    assert "500 of 2,000 points" in cloud.name
    meshes = {trace.name: trace for trace in figure.data if trace.type == "mesh3d"}
    assert set(meshes) == set(wall_decision.objects)
    pick = wall_decision.choice
    assert pick is not None and meshes[pick].hovertext[0] == hover_text(wall_decision, pick)
    assert "(pick)" in meshes[pick].hovertext[0] and "EC " in meshes[pick].hovertext[0]
    outline = next(trace for trace in figure.data if trace.name == f"{pick} outline")
    assert outline.line.color == "#e6007e"
    assert any(trace.marker.showscale for trace in figure.data if trace.type == "scatter3d" and trace.marker)
    steps = figure.layout.sliders[0].steps
    assert len(steps) == 41
    last = steps[-1].args[0]["visible"]
    assert last[0] and sum(last) == len(figure.data) - 3 * 40  # every box taken away, the cloud stays
    first_pick = steps[1].args[0]["visible"]
    assert first_pick.count(False) == 3  # the pick's mesh, outline and label
    label = next(trace for trace in figure.data if trace.name == f"{pick} label")
    assert label.text[0] == f"<b>1. {pick}</b>" and label.textfont.color == "#e6007e"
    assert [step.label for step in steps[:3]] == ["start", "1", "2"]  # short labels: 40 steps fit the width


def test_hover_names_the_strongest_relations() -> None:
    values = DecisionValues(
        ["a", "b", "c"], [0.1, 0.5, 2.0], [0.0, 0.02, 0.0],
        probabilities=[[0, 0.0, 0.0], [0.3, 0, 0.0], [0.9, 0.8, 0]], order=["a", "b", "c"],
    )  # fmt: skip
    text = hover_text(values, "c")
    assert text == "<b>c</b>  #3 in the plan<br>EC 2.00<br>supports a (0.90)<br>supports b (0.80)"
    assert "EC 0.50 ± 0.02" in hover_text(values, "b")
    assert hover_text(None, "x<y>") == "<b>x&lt;y&gt;</b>"


def test_the_sliders_titles_escape_the_heading_and_the_ids_as_the_first_title_does() -> None:
    """The slider's titles carried the heading and the ids raw ('</title><script>', "a'b")."""
    from unstack.scene import Box

    boxes = [Box("<b>x</b>", [0.4, 0.4, 0.4], [1.0, 0.0, 0.2]), Box("a'b", [0.4, 0.4, 0.4], [1.0, 0.0, 0.6])]
    scene = Scene(boxes, np.zeros((0, 3)), ["<b>x</b>", "a'b"])
    values = DecisionValues(["<b>x</b>", "a'b"], [1.0, 0.0], choice="a'b", order=["a'b", "<b>x</b>"])
    figure = build_view(scene, values=values, title="</title><script>")
    titles = [step.args[1]["title.text"] for step in figure.layout.sliders[0].steps]
    assert titles[0] == figure.layout.title.text == "&lt;/title&gt;&lt;script&gt; — pick a&#x27;b (EC 0.00)"
    assert titles[2] == "after 2 picks: a&#x27;b, &lt;b&gt;x&lt;/b&gt; taken away"


def test_the_page_needs_no_network(tmp_path: Path, wall: Scene, wall_decision: DecisionValues) -> None:
    target = tmp_path / "pile.html"
    size = write_view(wall, target, values=wall_decision)
    page = target.read_text()
    assert size == len(page.encode()) and size < 8_000_000
    assert re.search(r"<script[^>]*\bsrc=", page) is None  # plotly.js is inlined, nothing is fetched
    assert "Plotly.newPlot" in page


def test_the_same_scene_and_seed_give_the_same_page(tmp_path: Path, wall: Scene, wall_decision: DecisionValues) -> None:
    write_view(wall, tmp_path / "a.html", values=wall_decision)
    write_view(wall, tmp_path / "b.html", values=wall_decision)
    assert (tmp_path / "a.html").read_bytes() == (tmp_path / "b.html").read_bytes()


def test_bad_input(tmp_path: Path, wall: Scene) -> None:
    with pytest.raises(InvalidArgument, match="max_points must be a non-negative count, got -1"):
        write_view(wall, tmp_path / "x.html", max_points=-1)
    with pytest.raises(InvalidArgument, match=r"max_points must be at most 1,000,000 \(a page of about 60 MB"):
        write_view(wall, tmp_path / "x.html", max_points=5_000_000)
    with pytest.raises(InvalidArgument, match="the decision's boxes do not match"):
        write_view(wall, tmp_path / "x.html", values=DecisionValues(["zz"], [1.0]))
    assert not list(tmp_path.iterdir())


def chromium() -> str | None:
    return next((path for name in ("chromium", "chromium-browser") if (path := shutil.which(name))), None)


@pytest.mark.slow
@pytest.mark.skipif(chromium() is None, reason="no chromium binary (.ci/run installs Debian's chromium)")
def test_a_headless_browser_shows_the_scene(tmp_path: Path, wall: Scene, wall_decision: DecisionValues) -> None:
    from matplotlib.image import imread

    page, shot = tmp_path / "pile.html", tmp_path / "shot.png"
    write_view(wall, page, values=wall_decision, title="wall of 40")
    browser = chromium()
    assert browser is not None
    command = [
        browser, "--headless", "--no-sandbox", "--disable-gpu", "--use-gl=swiftshader", "--enable-unsafe-swiftshader",
        "--hide-scrollbars", f"--screenshot={shot}", "--window-size=1000,800", "--virtual-time-budget=8000",
        page.as_uri(),
    ]  # fmt: skip
    subprocess.run(command, capture_output=True, timeout=180, check=True, cwd=tmp_path)
    image = imread(shot)[:, :, :3]
    assert image.shape[:2] == (800, 1000)
    plot = image[60:640]  # below the title, above the slider
    share_not_white = float(np.mean(plot.min(axis=2) < 0.95))
    assert share_not_white > 0.15, share_not_white
    # viridis at both ends of the cost scale: dark purple (cheap boxes on top) and yellow (loaded boxes)
    red, green, blue = plot[..., 0], plot[..., 1], plot[..., 2]
    purple = (red > 0.2) & (red < 0.4) & (green < 0.2) & (blue > 0.3)
    yellow = (red > 0.75) & (green > 0.75) & (blue < 0.35)
    assert purple.sum() > 500 and yellow.sum() > 500, (int(purple.sum()), int(yellow.sum()))
