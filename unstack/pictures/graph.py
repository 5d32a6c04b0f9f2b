"""A support graph: boxes without geometry as nodes in layers, supporters below what they support.

Used when a file holds support probabilities but no scene. A box's layer is the longest
chain of probable supports (p >= threshold) below it; within a layer boxes are spread
evenly, ordered by where their supporters sit. Nodes are coloured by expected cost, the
pick is ringed in magenta, ``order`` numbers the unloading order, and arrows run from
supporter to supported, as wide as they are probable.

Examples
--------
>>> import tempfile, pathlib
>>> from unstack.pictures.values import DecisionValues
>>> values = DecisionValues(["top", "bottom"], [0.1, 0.9], choice="top", probabilities=[[0, 0.1], [0.9, 0]])
>>> layers(values.probabilities, 0.5).tolist()
[1, 0]
>>> target = pathlib.Path(tempfile.mkdtemp()) / "graph.png"
>>> render_support_graph(values, target)
>>> target.read_bytes()[:4]
b'\\x89PNG'
"""

from __future__ import annotations

import os
from typing import Any

import numpy as np

from unstack.checks import counted
from unstack.pictures.labels import LABEL_POINTS, place_labels
from unstack.pictures.panels import ARROW, HIGHLIGHT, CostColours, arrow_legend, arrow_width, box_label, draw_ranking
from unstack.pictures.values import DecisionValues, check_threshold

__all__ = ["draw_support_graph", "layers", "render_support_graph"]


def layers(probabilities: np.ndarray, threshold: float) -> np.ndarray:
    """Layer of each box: the longest chain of supports with p >= ``threshold`` beneath it.

    Mutual or cyclic supports are cut after ``n`` rounds (a cycle stays in a band of layers).

    Examples
    --------
    >>> layers(np.array([[0, 0.9, 0], [0, 0, 0.9], [0, 0, 0]]), 0.5).tolist()
    [0, 1, 2]
    """
    probable = (np.asarray(probabilities) >= max(threshold, 1e-12)) & ~np.eye(len(probabilities), dtype=bool)
    depth = np.zeros(len(probabilities), dtype=np.int64)
    for _ in range(len(probabilities)):
        below = np.where(probable, depth[:, None] + 1, 0).max(axis=0) if len(depth) else depth
        updated = np.maximum(depth, below)
        if np.array_equal(updated, depth):
            break
        depth = np.minimum(updated, len(probabilities) - 1)
    return depth


def _positions(values: DecisionValues, threshold: float, per_row: int = 8) -> np.ndarray:
    """Node centres: one band per layer, wrapped into rows of at most ``per_row`` boxes."""
    assert values.probabilities is not None
    weights = values.probabilities
    level = layers(weights, threshold)
    positions = np.zeros((len(values.objects), 2))
    row_y = 0.0
    for layer in range(int(level.max()) + 1 if len(level) else 0):
        members = [i for i in range(len(level)) if level[i] == layer]

        def key(i: int, layer: int = layer) -> tuple[float, str]:
            below = weights[:, i] * (level < layer)
            centre = float((below * positions[:, 0]).sum() / below.sum()) if below.sum() > 0 else 0.0
            return (centre, values.objects[i])

        members.sort(key=key)
        for start in range(0, len(members), per_row):
            row = members[start : start + per_row]
            for rank, i in enumerate(row):
                positions[i] = (rank - (len(row) - 1) / 2.0, row_y)
            row_y += 0.75
        row_y += 0.45
    return positions


def draw_support_graph(values: DecisionValues, *, threshold: float = 0.5, title: str | None = None) -> Any:
    """The support graph of ``values`` (which must carry probabilities) with the ranking beside it.

    Returns
    -------
    matplotlib.figure.Figure
    """
    from matplotlib.patches import Circle

    from unstack.errors import InvalidArgument
    from unstack.plotting import figure as new_figure

    threshold = check_threshold(threshold)
    if values.probabilities is None:
        raise InvalidArgument(f"{values.source}: a support graph needs support probabilities")
    positions = _positions(values, threshold)
    colours = CostColours(values)
    widest = max(np.unique(positions[:, 1], return_counts=True)[1].max(), 1) if len(positions) else 1
    top = float(positions[:, 1].max()) if len(positions) else 0.0
    graph_width = max(4.5, 0.95 * widest + 1.0)
    height = max(4.6, 1.25 * top + 2.2, 0.165 * len(values.objects) + 1.4)
    drawn = new_figure(figsize=(graph_width + 3.4, height))
    grid = drawn.add_gridspec(
        1, 3, width_ratios=[graph_width, 2.6, 0.12], left=0.02, right=0.93, top=0.9, bottom=0.09, wspace=0.28
    )
    axes = drawn.add_subplot(grid[0, 0])
    radius = 0.2
    for i, box in enumerate(values.objects):
        chosen = box == values.choice
        axes.add_patch(
            Circle(
                tuple(positions[i]),
                radius,
                facecolor=colours.of(box),
                edgecolor=HIGHLIGHT if chosen else "black",
                linewidth=3.0 if chosen else 0.8,
                zorder=5,
            )
        )
    arrows = values.arrows(threshold)
    for supporter, supported, probability in arrows:
        start, end = positions[values.index(supporter)], positions[values.index(supported)]
        mutual = values.probabilities[values.index(supported), values.index(supporter)] >= threshold
        bend = 0.25 if start[1] == end[1] or mutual else 0.0
        axes.annotate(
            "",
            xy=tuple(end),
            xytext=tuple(start),
            arrowprops={
                "arrowstyle": "-|>",
                "color": ARROW,
                "lw": arrow_width(probability, threshold),
                "alpha": 0.85,
                "shrinkA": 11,
                "shrinkB": 11,
                "mutation_scale": 10,
                "connectionstyle": f"arc3,rad={bend}",
            },
            zorder=3,
        )
    span_x = max(float(np.abs(positions[:, 0]).max()) if len(positions) else 0.0, 0.5) + 0.6
    axes.set_xlim(-span_x, span_x)
    axes.set_ylim(-0.6, top + 0.9)
    axes.set_aspect("equal", adjustable="box")
    axes.set_axis_off()
    axes.set_title(
        f"support graph ({counted(len(values.objects), 'box', 'boxes')}, {counted(len(arrows), 'arrow')}); "
        "supporters below",
        fontsize=LABEL_POINTS + 2,
    )
    arrow_legend(axes, threshold, f"P(X supports Y) ≥ {threshold:g}")
    ranking = drawn.add_subplot(grid[0, 1])
    draw_ranking(ranking, values, colours)
    colours.colour_bar(drawn, drawn.add_subplot(grid[0, 2]))
    if title:
        drawn.suptitle(title, fontsize=LABEL_POINTS + 4)
    drawn.canvas.draw()
    order = sorted(range(len(values.objects)), key=lambda i: (values.objects[i] != values.choice, values.objects[i]))
    place_labels(
        axes,
        [(float(positions[i, 0]), float(positions[i, 1])) for i in order],
        [box_label(values, values.objects[i]) for i in order],
        weights=["bold" if values.objects[i] == values.choice else "normal" for i in order],
        colours=[HIGHLIGHT if values.objects[i] == values.choice else "black" for i in order],
        step=7.0,
    )
    return drawn


def render_support_graph(
    values: DecisionValues,
    output: str | os.PathLike[str],
    *,
    threshold: float = 0.5,
    title: str | None = None,
    dpi: int = 110,
) -> None:
    """Draw :func:`draw_support_graph` into a PNG or SVG file, atomically."""
    from unstack.atomic import atomic_save_figure, check_output_path

    check_output_path(output)
    figure = draw_support_graph(values, threshold=threshold, title=title)
    atomic_save_figure(figure, output, dpi=dpi, bbox_inches="tight", pad_inches=0.08)
