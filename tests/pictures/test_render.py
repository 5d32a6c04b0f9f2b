"""Renders of a pile that show the decision: legible at 40 boxes, the pick marked, PNG and SVG."""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from tests.pictures.conftest import wall_values
from unstack.errors import InvalidArgument
from unstack.pictures.labels import LABEL_POINTS
from unstack.pictures.panels import HIGHLIGHT
from unstack.pictures.render import draw_scene, render_scene
from unstack.pictures.values import DecisionValues
from unstack.scene import Scene

pytestmark = pytest.mark.slow  # draws full matplotlib figures


def _box_labels(figure: Any) -> list[Any]:
    """The box labels of the sensor view (annotations with text), as drawn."""
    sensor = figure.axes[1]
    return [text for text in sensor.texts if text.get_text()]


def _ranking(figure: Any) -> Any:
    return next(axes for axes in figure.axes if axes.get_title().startswith("ranking"))


def _overlaps(figure: Any, texts: list[Any]) -> list[tuple[str, str]]:
    renderer = figure.canvas.get_renderer()
    extents = [text.get_window_extent(renderer) for text in texts]
    names = [getattr(text, "get_text", lambda: "legend")() for text in texts]
    return [
        (names[i], names[j])
        for i in range(len(texts))
        for j in range(i + 1, len(texts))
        if extents[i].overlaps(extents[j])
    ]


@pytest.mark.parametrize("seed", [0, 1])
def test_forty_labels_are_legible_and_do_not_overlap(seed: int) -> None:
    from tests.pictures.conftest import wall_scene

    scene = wall_scene(seed=seed)
    values = wall_values(scene, seed=seed, order=True)
    started = time.perf_counter()
    figure = draw_scene(scene, values=values, arrows=True, threshold=0.8)
    figure.canvas.draw()
    seconds = time.perf_counter() - started
    labels = _box_labels(figure)
    assert len(labels) == 40
    assert min(text.get_fontsize() for text in labels) >= 8
    assert not _overlaps(figure, labels)
    legend = figure.axes[1].get_legend()
    assert legend is not None and not _overlaps(figure, [*labels, legend])
    renderer = figure.canvas.get_renderer()
    frame = figure.axes[1].get_window_extent(renderer)
    assert all(frame.contains(*text.get_window_extent(renderer).get_points().mean(axis=0)) for text in labels)
    ranking = _ranking(figure)
    ticks = ranking.get_yticklabels()
    assert len(ticks) == 40 and min(tick.get_fontsize() for tick in ticks) >= 8
    assert not _overlaps(figure, list(ticks))
    assert seconds < 30, seconds


def test_the_pick_and_the_plan_are_shown(wall: Scene, wall_decision: DecisionValues) -> None:
    figure = draw_scene(wall, values=wall_decision)
    labels = {text.get_text(): text for text in _box_labels(figure)}
    pick = wall_decision.choice
    assert pick is not None and wall_decision.order[0] == pick
    chosen = labels[f"1. {pick}  ← pick"]
    assert chosen.get_color() == HIGHLIGHT and chosen.get_fontweight() == "bold"
    assert f"40. {wall_decision.order[-1]}" in labels
    ranking = _ranking(figure)
    ticks = [tick.get_text() for tick in ranking.get_yticklabels()]
    assert ticks[0] == pick and not any(". " in tick for tick in ticks)  # one numbering: the plan's, in the views
    assert any(type(container).__name__ == "ErrorbarContainer" for container in ranking.containers)  # sampled
    bar = figure.axes[2]
    assert "expected cost" in bar.get_ylabel() and "± s.e." in bar.get_ylabel()


def test_arrows_follow_the_threshold(wall: Scene, wall_decision: DecisionValues) -> None:
    assert wall_decision.probabilities is not None

    def arrows(threshold: float) -> int:
        figure = draw_scene(wall, values=wall_decision, arrows=True, threshold=threshold)
        return sum(1 for text in figure.axes[1].texts if not text.get_text())

    expected = [len(wall_decision.arrows(t)) for t in (0.2, 0.8, 1.0)]
    assert [arrows(t) for t in (0.2, 0.8, 1.0)] == expected
    assert expected[0] > expected[1] > 0


def test_truth_colouring_needs_no_decision(wall: Scene) -> None:
    figure = draw_scene(wall, colour="truth")
    assert figure.axes[-1].get_ylabel() == "boxes supported (ground truth)"
    assert len(_box_labels(figure)) == 40


@pytest.mark.parametrize("suffix", ["png", "svg"])
def test_png_and_svg(tmp_path: Path, wall: Scene, wall_decision: DecisionValues, suffix: str) -> None:
    target = tmp_path / f"pile.{suffix}"
    render_scene(wall, target, values=wall_decision, arrows=True)
    head = target.read_bytes()[:8]
    assert head == b"\x89PNG\r\n\x1a\n" if suffix == "png" else head.startswith(b"<?xml")
    assert [path.name for path in tmp_path.iterdir()] == [target.name]
    again = tmp_path / "again" / target.name
    again.parent.mkdir()
    render_scene(wall, again, values=wall_decision, arrows=True)
    if suffix == "png":  # the same picture, byte for byte
        assert again.read_bytes() == target.read_bytes()
    else:  # no date of writing in it (matplotlib's clipping path ids are random in every SVG)
        assert b"<dc:date>" not in target.read_bytes()


def test_bad_input_is_refused_before_writing(tmp_path: Path, wall: Scene, wall_decision: DecisionValues) -> None:
    target = tmp_path / "pile.png"
    with pytest.raises(InvalidArgument, match=r"threshold must be a probability in \[0, 1\], got 1.5"):
        render_scene(wall, target, values=wall_decision, threshold=1.5)
    stranger = DecisionValues(["nowhere", "b00"], [1.0, 2.0], source="d.json")
    with pytest.raises(InvalidArgument, match=r"d\.json: the decision's boxes do not match .*'nowhere' is not in"):
        render_scene(wall, target, values=stranger)
    with pytest.raises(InvalidArgument, match="colouring by expected cost needs a decision"):
        render_scene(wall, target)
    with pytest.raises(InvalidArgument, match="colour must be one of cost, truth, none, got 'red'"):
        render_scene(wall, target, values=wall_decision, colour="red")
    with pytest.raises(InvalidArgument, match=r"the folder .* does not exist"):
        render_scene(wall, tmp_path / "no" / "pile.png", values=wall_decision)
    assert not list(tmp_path.iterdir())


def test_label_size_is_the_shared_constant() -> None:
    assert LABEL_POINTS >= 8
    assert np.isfinite(LABEL_POINTS)


def test_the_pick_is_painted_last_in_the_oblique_view(wall: Scene, wall_decision: DecisionValues) -> None:
    figure = draw_scene(wall, values=wall_decision)
    oblique = figure.axes[0]
    assert oblique.computed_zorder is False
    last = oblique.collections[-1]  # painted over every other box
    assert last.get_linewidth()[0] == max(collection.get_linewidth()[0] for collection in oblique.collections)


@pytest.mark.parametrize("side_m", [5.0, 50.0])
def test_a_box_out_of_the_sensors_view_is_labelled_at_the_panels_edge(side_m: float) -> None:
    """Its label was drawn where it projects, beyond the panel: at 50 m the picture grew to 11,399 px."""
    from unstack.scene import Box
    from unstack.understanding.clouds import surface_cloud

    near, far = Box("b00", [0.4, 0.4, 0.4], [1.5, 0.0, 0.2]), Box("b01", [0.4, 0.4, 0.4], [1.5, side_m, 0.2])
    scene = Scene([near, far], surface_cloud([near], spacing=0.02, seed=0), ["b00", "b01"])
    values = DecisionValues(["b00", "b01"], [0.5, 0.0], choice="b01")
    figure = draw_scene(scene, values=values)
    sensor = figure.axes[1]
    frame = sensor.get_window_extent(figure.canvas.get_renderer())
    [label] = [text for text in _box_labels(figure) if text.get_text().startswith("b01")]
    assert label.get_text().endswith("(out of view)")
    x, y = sensor.transData.transform(label.xy)
    assert frame.x0 - 1 <= x <= frame.x1 + 1 and frame.y0 - 1 <= y <= frame.y1 + 1


def test_a_long_id_is_drawn_shortened_in_every_panel() -> None:
    """A 200-character id was one label across all three panels, and the PNG widened to hold it."""
    from unstack.pictures.panels import LONGEST_DRAWN_ID
    from unstack.scene import Box
    from unstack.understanding.clouds import surface_cloud

    long_id = "carton-" + "x" * 180 + "-end"
    boxes = [Box("b00", [0.4, 0.4, 0.4], [1.5, 0.0, 0.2]), Box(long_id, [0.4, 0.4, 0.4], [1.5, 0.5, 0.2])]
    scene = Scene(boxes, surface_cloud(boxes, spacing=0.02, seed=0), ["b00", long_id])
    figure = draw_scene(scene, values=DecisionValues(["b00", long_id], [0.5, 0.0], choice=long_id))
    figure.canvas.draw()
    texts = [text.get_text() for axes in figure.axes for text in [*axes.texts, *axes.get_yticklabels()]]
    assert all(len(text) < LONGEST_DRAWN_ID + 20 for text in texts), max(texts, key=len)
    assert any(text.startswith("carton-") and text.endswith("…xx-end") for text in texts)


def test_costs_all_zero_get_a_scale_of_one_box() -> None:
    """The colour bar read 1e-9 and the ranking's axis 1e-6 when every expected cost was 0."""
    from unstack.scene import Box

    boxes = [Box("a", [0.4, 0.4, 0.4], [1.5, 0.0, 0.2]), Box("b", [0.4, 0.4, 0.4], [1.5, 0.5, 0.2])]
    scene = Scene(boxes, np.zeros((0, 3)), ["a", "b"])
    figure = draw_scene(scene, values=DecisionValues(["a", "b"], [0.0, 0.0], choice="a"))
    limits = [axes.get_xlim()[1] for axes in figure.axes if axes.get_xlabel() == "expected cost"]
    scales = [image.norm.vmax for axes in figure.axes for image in axes.collections if image.get_array() is not None]
    assert limits == [1.0] and scales and set(scales) == {1.0}
