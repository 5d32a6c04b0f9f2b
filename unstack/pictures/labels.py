"""Labels that do not overlap: each is tried at its anchor, then at growing offsets around it.

A label that had to move gets a thin leader line to its anchor. Placement is measured on the
drawn figure (text extents from the renderer), so the figure's layout must be final first.

Examples
--------
>>> from unstack.plotting import subplots
>>> drawn, axes = subplots(figsize=(3, 3))
>>> axes.set_xlim(0, 1); axes.set_ylim(0, 1)  # doctest: +ELLIPSIS
(...)
>>> texts = place_labels(axes, [(0.5, 0.5), (0.5, 0.5)], ["first", "second"])
>>> first, second = text_extents(texts)
>>> bool(first.overlaps(second))
False
"""

from __future__ import annotations

import functools
from collections.abc import Sequence
from typing import Any

import numpy as np

__all__ = ["LABEL_POINTS", "place_labels", "text_extents"]

#: Font size of box labels (points): legible in print and on a screen.
LABEL_POINTS = 8.0


def text_extents(texts: Sequence[Any]) -> list[Any]:
    """Display-space extents of the texts themselves (an annotation's own extent includes its leader line)."""
    from matplotlib.text import Text

    if not texts:
        return []
    renderer = texts[0].figure.canvas.get_renderer()
    return [Text.get_window_extent(text, renderer) for text in texts]


def _candidates(step: float, rings: int) -> list[tuple[float, float]]:
    """Offsets in points: the anchor, then rings of 8, 12, 16, ... directions at growing distance."""
    offsets = [(0.0, 0.0)]
    for ring in range(1, rings + 1):
        count = 4 + 4 * ring
        radius = step * ring
        for k in range(count):
            angle = np.pi / 2 + 2 * np.pi * k / count
            offsets.append((radius * 1.6 * float(np.cos(angle)), radius * float(np.sin(angle))))
    return offsets


def _in_frame(axes: Any, frame: Any, anchor: Sequence[float], text: str) -> tuple[tuple[float, float], str]:
    """An anchor outside the axes pinned to their edge, its label saying so (a box out of the
    sensor's view was labelled far off the panel, and the picture grew to hold the label)."""
    x, y = axes.transData.transform(tuple(anchor))
    inside_x, inside_y = min(max(x, frame.x0), frame.x1), min(max(y, frame.y0), frame.y1)
    if (inside_x, inside_y) == (x, y):
        return (float(anchor[0]), float(anchor[1])), text
    pinned = axes.transData.inverted().transform((inside_x, inside_y))
    return (float(pinned[0]), float(pinned[1])), f"{text} (out of view)"


def place_labels(
    axes: Any,
    anchors: Sequence[Sequence[float]],
    texts: Sequence[str],
    *,
    fontsize: float = LABEL_POINTS,
    weights: Sequence[str] | None = None,
    colours: Sequence[Any] | None = None,
    step: float = 9.0,
    rings: int = 9,
) -> list[Any]:
    """Put ``texts`` near ``anchors`` (data coordinates) so that no two labels overlap.

    Labels are placed in the given order (put the important ones first). A label that
    finds no free place within ``rings`` rings is put at its anchor (the overlap is then
    visible rather than hidden). An anchor outside the axes is pinned to their edge and its
    label ends "(out of view)".

    Parameters
    ----------
    axes : matplotlib.axes.Axes
        Two-dimensional axes whose figure has its final layout.
    anchors : sequence of (x, y)
    texts : sequence of str
    fontsize : float
    weights : sequence of str, optional
        ``"bold"`` or ``"normal"`` per label.
    colours : sequence of colour, optional
        Text colour per label.
    step, rings : float, int
        Distance between rings (points) and how many rings to try.

    Returns
    -------
    list of matplotlib.text.Annotation
    """
    figure = axes.figure
    renderer = figure.canvas.get_renderer()
    frame = axes.get_window_extent(renderer)
    taken: list[Any] = []
    placed: list[Any] = []
    pixels_per_point = figure.dpi / 72.0
    margin = 1.5 * pixels_per_point
    style = {"boxstyle": "round,pad=0.15", "facecolor": "white", "edgecolor": "none", "alpha": 0.85}
    for index, (given, label_text) in enumerate(zip(anchors, texts, strict=True)):
        anchor, text = _in_frame(axes, frame, given, label_text)
        weight = weights[index] if weights is not None else "normal"
        colour = colours[index] if colours is not None else "black"
        annotate = functools.partial(
            axes.annotate, text, xy=tuple(anchor), textcoords="offset points", ha="center", va="center",
            fontsize=fontsize, fontweight=weight, color=colour, zorder=20, annotation_clip=False,
        )  # fmt: skip

        chosen: Any = None
        for offset in _candidates(step, rings):
            trial = annotate(xytext=offset)
            extent = trial.get_window_extent(renderer).expanded(1.0, 1.0).padded(margin)
            inside = frame.x0 <= extent.x0 and extent.x1 <= frame.x1 and frame.y0 <= extent.y0 and extent.y1 <= frame.y1
            if inside and not any(extent.overlaps(other) for other in taken):
                trial.remove()
                chosen = (offset, extent)
                break
            trial.remove()
        offset, extent = chosen if chosen is not None else ((0.0, 0.0), None)
        moved = offset != (0.0, 0.0)
        leader = {"arrowstyle": "-", "color": "0.25", "lw": 0.6, "shrinkA": 0, "shrinkB": 0}
        label = annotate(xytext=offset, bbox=style, arrowprops=leader if moved else None)
        if extent is None:
            extent = text_extents([label])[0].padded(margin)
        taken.append(extent)
        placed.append(label)
    return placed
