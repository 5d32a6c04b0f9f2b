"""What every decision picture shares: the cost colours, the highlight of the pick, the ranking panel.

Examples
--------
>>> from unstack.pictures.values import DecisionValues
>>> colours = CostColours(DecisionValues(["a", "b"], [0.0, 2.0]))
>>> colours.of("a") != colours.of("b")
True
"""

from __future__ import annotations

from typing import Any

import numpy as np

from unstack.pictures.labels import LABEL_POINTS
from unstack.pictures.values import DecisionValues

__all__ = [
    "HIGHLIGHT",
    "LONGEST_DRAWN_ID",
    "CostColours",
    "arrow_legend",
    "arrow_width",
    "box_label",
    "draw_ranking",
    "drawn_id",
]

#: Edge colour of the chosen box (no colour of the cost map is near it).
HIGHLIGHT = "#e6007e"
#: Colour of support arrows.
ARROW = "#d95f02"


class CostColours:
    """Expected cost -> colour (viridis: dark = cheap to unload first, yellow = costly)."""

    def __init__(self, values: DecisionValues) -> None:
        from matplotlib import colormaps
        from matplotlib.colors import Normalize

        self.values = values
        self.cmap = colormaps["viridis"]
        top = float(np.max(values.expected_costs + values.expected_cost_errors)) if len(values.objects) else 1.0
        self.norm = Normalize(0.0, top if top > 0 else 1.0)  # all costs 0: a scale of one box, not of 1e-9

    def of(self, box: str) -> tuple[float, float, float, float]:
        """RGBA of ``box``'s EC."""
        rgba = self.cmap(self.norm(self.values.cost_of(box)))
        return (float(rgba[0]), float(rgba[1]), float(rgba[2]), float(rgba[3]))

    def colour_bar(self, figure: Any, cax: Any) -> Any:
        """A colour bar of EC in ``cax``."""
        from matplotlib.cm import ScalarMappable

        bar = figure.colorbar(ScalarMappable(norm=self.norm, cmap=self.cmap), cax=cax)
        label = self.values.cost_name + (" (bars: ± s.e.)" if self.values.sampled else "")
        bar.set_label(label, fontsize=LABEL_POINTS + 1)
        bar.ax.tick_params(labelsize=LABEL_POINTS)
        return bar


#: Ids longer than this many characters are drawn shortened in pictures (a 200-character id was
#: one label across every panel, and widened the picture to hold it).
LONGEST_DRAWN_ID = 24


def drawn_id(box: str) -> str:
    """A box id as a picture draws it: whole up to :data:`LONGEST_DRAWN_ID` characters, else its
    start and end around an ellipsis.

    Examples
    --------
    >>> drawn_id("b04")
    'b04'
    >>> drawn_id("carton-" + "x" * 40 + "-17")
    'carton-xxxxxxxx…xxx-17'
    """
    if len(box) <= LONGEST_DRAWN_ID:
        return box
    return f"{box[:15]}…{box[-6:]}"


def box_label(values: DecisionValues, box: str) -> str:
    """A box's label: its id, with its place in the plan when there is one (``"3. b04"``).

    Examples
    --------
    >>> box_label(DecisionValues(["a", "b"], [0, 1], order=["b", "a"]), "a")
    '2. a'
    """
    number = values.plan_number(box)
    return f"{number}. {drawn_id(box)}" if number is not None else drawn_id(box)


def arrow_width(probability: float, threshold: float) -> float:
    """Line width (points) of a support arrow: 0.8 at the threshold, 3 at certainty.

    Examples
    --------
    >>> arrow_width(1.0, 0.5)
    3.0
    """
    span = max(1.0 - threshold, 1e-9)
    return 0.8 + 2.2 * min(max((probability - threshold) / span, 0.0), 1.0)


def arrow_legend(axes: Any, threshold: float, label: str) -> None:
    """A legend of arrow widths (the threshold, the middle, certainty) below the axes, clear of the labels."""
    from matplotlib.lines import Line2D

    levels = sorted({threshold, round((threshold + 1.0) / 2.0, 2), 1.0})
    handles = [Line2D([], [], color=ARROW, lw=arrow_width(p, threshold)) for p in levels]
    axes.legend(
        handles,
        [f"{p:.2f}" for p in levels],
        title=label,
        title_fontsize=LABEL_POINTS,
        fontsize=LABEL_POINTS,
        loc="upper center",
        bbox_to_anchor=(0.5, -0.01),
        ncol=len(levels),
        frameon=False,
    )


def draw_ranking(axes: Any, values: DecisionValues, colours: CostColours) -> None:
    """Horizontal bars of EC, cheapest on top; the pick outlined; error bars where sampled."""
    order = sorted(range(len(values.objects)), key=lambda i: (float(values.expected_costs[i]), values.objects[i]))
    if values.choice is not None:
        chosen = values.index(values.choice)
        order.remove(chosen)
        order.insert(0, chosen)
    ids = [values.objects[i] for i in order]
    rows = np.arange(len(ids))
    costs = values.expected_costs[order]
    errors = values.expected_cost_errors[order]
    axes.barh(
        rows,
        costs,
        xerr=errors if values.sampled else None,
        color=[colours.of(box) for box in ids],
        edgecolor=[HIGHLIGHT if box == values.choice else "none" for box in ids],
        linewidth=2.0,
        error_kw={"elinewidth": 1.0, "capsize": 2.0, "ecolor": "0.2"},
        height=0.75,
    )
    axes.set_yticks(
        rows, [drawn_id(box) for box in ids], fontsize=LABEL_POINTS
    )  # ids only: the plan's numbers are the 3D panel's
    for tick, box in zip(axes.get_yticklabels(), ids, strict=True):
        if box == values.choice:
            tick.set_color(HIGHLIGHT)
            tick.set_fontweight("bold")
    axes.set_ylim(len(ids) - 0.5, -0.5)
    top = float(np.max(costs + errors)) * 1.08 if len(ids) else 0.0
    axes.set_xlim(0.0, top if top > 0 else 1.0)
    axes.tick_params(axis="x", labelsize=LABEL_POINTS)
    axes.set_xlabel("expected cost", fontsize=LABEL_POINTS + 1)
    title = "ranking (pick on top)" if values.choice is not None else "ranking"
    axes.set_title(title, fontsize=LABEL_POINTS + 2)
    for side in ("top", "right"):
        axes.spines[side].set_visible(False)
