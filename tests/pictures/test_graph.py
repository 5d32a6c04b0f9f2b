"""The support graph of a supports file: layers, legible labels, the pick ringed."""

from __future__ import annotations

import itertools
from pathlib import Path

import numpy as np
import pytest

import unstack
from unstack.errors import InvalidArgument
from unstack.pictures.graph import draw_support_graph, layers, render_support_graph
from unstack.pictures.panels import HIGHLIGHT
from unstack.pictures.values import DecisionValues

pytestmark = pytest.mark.slow  # draws full matplotlib figures


def test_layers_put_supporters_below(rng: np.random.Generator) -> None:
    n = 12
    order = rng.permutation(n)
    probabilities = np.zeros((n, n))
    for below, above in itertools.pairwise(order):
        probabilities[below, above] = rng.uniform(0.6, 1.0)
    level = layers(probabilities, 0.5)
    assert level[order].tolist() == list(range(n))
    assert layers(probabilities, 1.0).tolist() == [0] * n or level.max() == n - 1


def test_mutual_support_terminates() -> None:
    level = layers(np.array([[0, 0.9], [0.9, 0]]), 0.5)
    assert level.max() <= 1


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_forty_boxes_are_legible(seed: int) -> None:
    rng = np.random.default_rng(seed)
    n = 40
    probabilities = np.where(rng.random((n, n)) < 0.04, rng.uniform(0.5, 1.0, (n, n)), rng.uniform(0, 0.2, (n, n)))
    np.fill_diagonal(probabilities, 0.0)
    ids = [f"b{k:02d}" for k in range(n)]
    costs = probabilities.sum(axis=1)
    values = DecisionValues(ids, costs, choice=ids[int(np.argmin(costs))], probabilities=probabilities)
    figure = draw_support_graph(values, threshold=0.5)
    figure.canvas.draw()
    renderer = figure.canvas.get_renderer()
    labels = [text for text in figure.axes[0].texts if text.get_text()]
    assert len(labels) == n and min(text.get_fontsize() for text in labels) >= 8
    extents = [text.get_window_extent(renderer) for text in labels]
    assert not [(i, j) for i in range(n) for j in range(i + 1, n) if extents[i].overlaps(extents[j])]
    chosen = [text for text in labels if text.get_text() == values.choice]
    assert chosen and chosen[0].get_color() == HIGHLIGHT


def test_a_supports_file_is_drawn(tmp_path: Path, examples: Path) -> None:
    decision = unstack.decide(unstack.load_supports(examples / "pile31.supports.json"), seed=0)
    values = DecisionValues(
        decision.objects, decision.expected_costs, decision.expected_cost_errors,
        choice=decision.choice, probabilities=decision.marginals,
    )  # fmt: skip
    target = tmp_path / "graph.svg"
    render_support_graph(values, target, threshold=0.6)
    assert target.read_text().lstrip().startswith("<?xml")
    with pytest.raises(InvalidArgument, match="a support graph needs support probabilities"):
        render_support_graph(DecisionValues(["a"], [0.0]), tmp_path / "none.png")
    with pytest.raises(InvalidArgument, match="threshold must be a probability"):
        render_support_graph(values, tmp_path / "none.png", threshold=-1)
    assert [path.name for path in tmp_path.iterdir()] == ["graph.svg"]
