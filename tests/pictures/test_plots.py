"""Curves that coincide are told apart: markers, line styles and a note in the legend."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from unstack.plotting import curve_labels


def test_curve_labels_name_the_twin() -> None:
    assert curve_labels(["a", "b", "c"], [[0, 1], [0, 1.0 + 1e-12], [0, 2]]) == ["a", "b (same curve as a)", "c"]
    assert curve_labels(["a", "b"], [[0, float("nan")], [0, float("nan")]]) == ["a", "b (same curve as a)"]
    assert curve_labels(["a", "b"], [[0, 1], [0, 1.1]]) == ["a", "b"]


def _steps(moved: list[int]) -> dict[str, Any]:
    return {"steps": [{"boxes_moved": count} for count in moved]}


def test_the_unloading_figure_shows_every_curve(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    import unstack.plotting
    from unstack.experiments.unloading import plot_unloading

    drawn: list[Any] = []
    monkeypatch.setattr(unstack.plotting, "save_figure", lambda figure, output: drawn.append(figure))
    runs = {"reasoner": [1, 2, 1], "highest": [0, 1, 1], "free": [0, 1, 1], "random": [3, 3, 3]}
    result = {
        "makers": list(runs),
        "piles": [{"runs": {maker: _steps(moved) for maker, moved in runs.items()}}],
        "configs": 1,
        "data": "piles",
    }
    plot_unloading(result, tmp_path / "unloading.png")
    axes = drawn[0].axes[0]
    lines = axes.get_lines()
    assert [line.get_label() for line in lines] == ["reasoner", "highest", "free (same curve as highest)", "random"]
    assert len({(line.get_marker(), line.get_linestyle()) for line in lines}) == 4
    assert lines[2].get_markerfacecolor() == "none" and lines[2].get_markersize() > lines[1].get_markersize()
    legend = [text.get_text() for text in axes.get_legend().get_texts()]
    assert "free (same curve as highest)" in legend
