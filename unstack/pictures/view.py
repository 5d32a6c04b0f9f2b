"""An interactive 3D page of a pile: one self-contained HTML file (plotly's JavaScript inlined).

Detected boxes are solid and coloured by expected cost (a colour bar), outlined in black
(the pick in magenta); undetected boxes are faint grey; the point cloud is cut to the boxes'
surroundings, without the floor and the points on detected boxes (they would hide the pile),
and subsampled.
Hovering over a box shows its id, its EC (± standard error where sampled) and its
strongest support relations. With an unloading order, a slider steps through it, taking
the boxes away one by one. The page needs no network: open it from a disk or a mail.

plotly is imported only here, when a page is made.

Examples
--------
>>> import tempfile, pathlib
>>> from unstack.scene import Box, Scene
>>> from unstack.pictures.panels import box_label
>>> from unstack.pictures.values import DecisionValues
>>> scene = Scene([Box("a", [0.6, 0.4, 0.4], [1.0, 0.0, 0.2]), Box("b", [0.4, 0.3, 0.3], [1.0, 0.0, 0.55])],
...               points=[[0.7, 0.0, 0.5]], detected=["a", "b"])
>>> values = DecisionValues(["a", "b"], [1.0, 0.0], choice="b", order=["b", "a"], probabilities=[[0, 0.9], [0, 0]])
>>> target = pathlib.Path(tempfile.mkdtemp()) / "pile.html"
>>> write_view(scene, target, values=values) > 1_000_000  # bytes, the JavaScript included
True
>>> "<script src=" in target.read_text()  # plotly's JavaScript is in the page, nothing is fetched
False
"""

from __future__ import annotations

import html
import os
from typing import Any

import numpy as np

from unstack.errors import InvalidArgument
from unstack.geometry import BOX_FACES, box_corners, points_in_box
from unstack.pictures.values import DecisionValues
from unstack.scene import Box, Scene

__all__ = ["MAX_VIEW_POINTS", "build_view", "hover_text", "write_view"]

#: Most cloud points a page shows: about 60 MB of page, which a browser still opens (5 million
#: points made a page of 292 MB).
MAX_VIEW_POINTS = 1_000_000

HIGHLIGHT = "#e6007e"
#: Cloud points farther than this (m) outside the boxes' bounding box are left out.
NEAR = 0.15
#: Triangles of a box: each face of :data:`BOX_FACES` split along a diagonal.
TRIANGLES = np.array([tri for a, b, c, d in BOX_FACES for tri in ((a, b, c), (a, c, d))], dtype=np.int64)


def _edges(box: Box) -> tuple[list[float | None], list[float | None], list[float | None]]:
    """The outline of a box as one polyline per face, separated by gaps (None)."""
    corners = box_corners(box)
    xs: list[float | None] = []
    ys: list[float | None] = []
    zs: list[float | None] = []
    for face in BOX_FACES:
        for k in (*face, face[0]):
            xs.append(float(corners[k, 0]))
            ys.append(float(corners[k, 1]))
            zs.append(float(corners[k, 2]))
        xs.append(None)
        ys.append(None)
        zs.append(None)
    return xs, ys, zs


def hover_text(values: DecisionValues | None, box: str) -> str:
    """What hovering over ``box`` shows: id, EC ± s.e., the strongest support relations.

    Examples
    --------
    >>> values = DecisionValues(["a", "b"], [0.2, 1.0], [0.0, 0.05], choice="a", probabilities=[[0, 0.1], [0.9, 0]])
    >>> hover_text(values, "b")
    '<b>b</b><br>EC 1.00 ± 0.05<br>supports a (0.90)<br>rests on a (0.10)'
    """
    if values is None or box not in values.objects:
        return f"<b>{html.escape(box)}</b>"
    lines = [f"<b>{html.escape(box)}</b>" + ("  (pick)" if box == values.choice else "")]
    number = values.plan_number(box)
    if number is not None:
        lines[0] += f"  #{number} in the plan"
    lines.append(values.cost_text(box))
    lines += [f"{kind} {html.escape(other)} ({p:.2f})" for kind, other, p in values.strongest(box)]
    return "<br>".join(lines)


def _mesh(go: Any, boxes: list[Box], **style: Any) -> Any:
    corners = np.concatenate([box_corners(box) for box in boxes])
    triangles = np.concatenate([TRIANGLES + 8 * k for k in range(len(boxes))])
    return go.Mesh3d(
        x=corners[:, 0],
        y=corners[:, 1],
        z=corners[:, 2],
        i=triangles[:, 0],
        j=triangles[:, 1],
        k=triangles[:, 2],
        flatshading=True,
        hovertemplate="%{hovertext}<extra></extra>",
        **style,
    )


def build_view(
    scene: Scene,
    *,
    values: DecisionValues | None = None,
    max_points: int = 20_000,
    seed: int = 0,
    title: str | None = None,
) -> Any:
    """The plotly figure of the page (see the module).

    Parameters
    ----------
    scene : Scene
    values : DecisionValues, optional
        The decision: EC colours, the pick, hover text; ``values.order`` adds the slider.
    max_points : int
        At most this many cloud points are shown (a seeded random subset; at most
        :data:`MAX_VIEW_POINTS`).
    seed : int
        Seed of that subset.
    title : str, optional

    Returns
    -------
    plotly.graph_objects.Figure
    """
    import plotly.graph_objects as go
    from plotly.colors import sample_colorscale

    if isinstance(max_points, bool) or not isinstance(max_points, int | np.integer) or max_points < 0:
        raise InvalidArgument(f"max_points must be a non-negative count, got {max_points!r}")
    if max_points > MAX_VIEW_POINTS:
        raise InvalidArgument(
            f"max_points must be at most {MAX_VIEW_POINTS:,} (a page of about 60 MB; more will not open well "
            f"in a browser), got {max_points:,}"
        )
    if not scene.boxes:
        raise InvalidArgument(f"{scene.source}: the scene has no boxes to show")
    if values is not None:
        values.check_boxes(scene.box_ids, scene.source)
    detected = set(scene.detected) | (set(values.objects) if values is not None else set())
    top = float(np.max(values.expected_costs + values.expected_cost_errors)) if values is not None else 1.0
    top = top if top > 0 else 1.0  # all costs 0: a scale of one box
    traces: list[Any] = []
    points = scene.points
    if len(points):  # the cloud near the boxes, off the floor and off the detected boxes: context, not clutter
        corners = np.concatenate([box_corners(box) for box in scene.boxes])
        low, high = corners.min(axis=0) - NEAR, corners.max(axis=0) + NEAR
        keep = np.all((points >= low) & (points <= high), axis=1) & (points[:, 2] > low[2] + NEAR)
        for box in scene.boxes:  # a detected box's own points would only speckle its faces
            if box.id in detected:
                keep &= ~points_in_box(points, box, margin=0.04)
        points = points[keep]
    near = len(points)
    if len(points) > max_points:
        points = points[np.sort(np.random.default_rng(seed).choice(len(points), max_points, replace=False))]
    traces.append(
        go.Scatter3d(
            x=points[:, 0],
            y=points[:, 1],
            z=points[:, 2],
            mode="markers",
            marker={"size": 1.2, "color": "rgb(60,60,60)"},
            opacity=0.18,  # the trace's opacity: dark points, faint, never a white veil over the boxes
            hoverinfo="skip",
            name=f"cloud ({len(points):,} of {near:,} points: near the boxes, not on a detected one)",
        )
    )
    hidden = [box for box in scene.boxes if box.id not in detected]
    if hidden:
        texts = [f"{html.escape(box.id)} (not detected)" for box in hidden for _ in range(8)]
        traces.append(_mesh(go, hidden, color="lightgrey", opacity=0.25, hovertext=texts, name="not detected"))
    box_traces: dict[str, list[int]] = {}
    for box in scene.boxes:
        if box.id not in detected:
            continue
        if values is not None and box.id in values.objects:
            colour = sample_colorscale("Viridis", [min(values.cost_of(box.id) / top, 1.0)])[0]
        else:
            colour = "rgb(180,180,180)"
        chosen = values is not None and box.id == values.choice
        text = hover_text(values, box.id)
        box_traces[box.id] = [len(traces), len(traces) + 1, len(traces) + 2]
        traces.append(_mesh(go, [box], color=colour, opacity=1.0, hovertext=[text] * 8, name=box.id, showlegend=False))
        xs, ys, zs = _edges(box)
        traces.append(
            go.Scatter3d(
                x=xs,
                y=ys,
                z=zs,
                mode="lines",
                line={"color": HIGHLIGHT if chosen else "black", "width": 7 if chosen else 2.5},
                hoverinfo="skip",
                showlegend=False,
                name=f"{box.id} outline",
            )
        )
        number = values.plan_number(box.id) if values is not None else None
        label = html.escape(box.id if number is None else f"{number}. {box.id}")
        traces.append(  # the id (with its place in the plan) just above the box, taken away with it
            go.Scatter3d(
                x=[box.position[0]],
                y=[box.position[1]],
                z=[float(box_corners(box)[:, 2].max()) + 0.06],
                mode="text",
                text=[f"<b>{label}</b>" if chosen else label],
                textfont={"size": 15 if chosen else 13, "color": HIGHLIGHT if chosen else "black"},
                hoverinfo="skip",
                showlegend=False,
                name=f"{box.id} label",
            )
        )
    if values is not None:
        traces.append(
            go.Scatter3d(
                x=[None],
                y=[None],
                z=[None],
                mode="markers",
                marker={
                    "color": [0.0],
                    "colorscale": "Viridis",
                    "cmin": 0.0,
                    "cmax": top,
                    "showscale": True,
                    "colorbar": {"title": {"text": values.cost_name}, "thickness": 14, "len": 0.6},
                },
                hoverinfo="skip",
                showlegend=False,
            )
        )
    figure = go.Figure(traces)
    heading = title or scene.source
    if values is not None and values.choice is not None:
        heading += f" — pick {values.choice} ({values.cost_text(values.choice)})"
    figure.update_layout(
        title={"text": html.escape(heading), "x": 0.02},
        margin={"l": 0, "r": 0, "t": 40, "b": 0},
        legend={"x": 0.01, "y": 0.95},
        scene={
            "aspectmode": "data",
            "xaxis": {"title": {"text": "x (into container, m)"}},
            "yaxis": {"title": {"text": "y (m)"}},
            "zaxis": {"title": {"text": "z (m)"}},
            "camera": {"eye": {"x": -1.6, "y": -0.95, "z": 0.85}},  # from the door side
        },
    )
    if values is not None and values.order:  # the slider below the scene, inside the page
        figure.update_layout(sliders=[_plan_slider(values, box_traces, len(traces), heading)], margin={"b": 90})
    return figure


def _plan_slider(
    values: DecisionValues, box_traces: dict[str, list[int]], n_traces: int, heading: str
) -> dict[str, Any]:
    """Slider steps 0..n: step k has the first k boxes of the order taken away."""
    steps = []
    for k in range(len(values.order) + 1):
        visible = [True] * n_traces
        for box in values.order[:k]:
            for index in box_traces.get(box, []):
                visible[index] = False
        if k == 0:
            label, text = "start", html.escape(heading)
        else:
            label = str(k)  # short: 40 steps fit the page's width; the title names the boxes
            taken = ", ".join(html.escape(box) for box in values.order[:k])
            text = f"after {k} pick{'s' if k > 1 else ''}: {taken} taken away"
        steps.append({"label": label, "method": "update", "args": [{"visible": visible}, {"title.text": text}]})
    return {"active": 0, "currentvalue": {"prefix": "picks taken: "}, "pad": {"t": 10, "b": 10}, "x": 0.05, "len": 0.9,
            "y": 0, "yanchor": "top", "font": {"size": 11}, "steps": steps}  # fmt: skip


def write_view(scene: Scene, output: str | os.PathLike[str], **options: Any) -> int:
    """Write the page of :func:`build_view` (``options`` as there) to ``output``, atomically.

    Returns
    -------
    int
        Size of the page in bytes.
    """
    from unstack.atomic import atomic_write_text, check_output_path

    check_output_path(output)
    figure = build_view(scene, **options)
    page = figure.to_html(  # a fixed element id: the same scene and seed give the same bytes
        include_plotlyjs=True, full_html=True, config={"displaylogo": False, "responsive": True}, div_id="unstack-view"
    )
    atomic_write_text(output, page)
    return len(page.encode("utf-8"))
