"""Pictures of a pile that show the decision: an oblique view, the sensor's view and the ranking.

Detected boxes are coloured by their expected cost (a colour bar beside the sensor view; the
ranking panel shows every EC with its standard error where it was sampled); the chosen box
is outlined in magenta and named; ``order`` numbers the unloading order; support relations
at or above a threshold are arrows from supporter to supported, as wide as they are
probable. Without a decision the boxes are coloured by the ground truth (how many boxes each
supports), or grey. Labels are 8 pt and never overlap (see :mod:`unstack.pictures.labels`).

Examples
--------
>>> import tempfile, pathlib
>>> from unstack.scene import Box, Scene
>>> from unstack.pictures.values import DecisionValues
>>> scene = Scene([Box("a", [0.6, 0.4, 0.4], [1.0, 0.0, 0.2]), Box("b", [0.4, 0.3, 0.3], [1.0, 0.0, 0.55])],
...               points=[[0.7, 0.0, 0.5]], detected=["a", "b"], ground_truth=[[0, 1], [0, 0]])
>>> values = DecisionValues(["a", "b"], [1.0, 0.0], choice="b", probabilities=[[0, 0.9], [0, 0]])
>>> target = pathlib.Path(tempfile.mkdtemp()) / "pile.svg"
>>> render_scene(scene, target, values=values, arrows=True)
>>> target.read_text()[:5]
'<?xml'
"""

from __future__ import annotations

import os
from collections.abc import Callable
from typing import Any

import numpy as np

from unstack.checks import counted
from unstack.errors import InvalidArgument
from unstack.geometry import BOX_FACES, box_corners, convex_hull_2d
from unstack.pictures.camera import Camera
from unstack.pictures.labels import LABEL_POINTS, place_labels
from unstack.pictures.panels import (
    ARROW,
    HIGHLIGHT,
    CostColours,
    arrow_legend,
    arrow_width,
    box_label,
    draw_ranking,
    drawn_id,
)
from unstack.pictures.values import DecisionValues, check_threshold
from unstack.scene import Scene

__all__ = ["COLOURINGS", "draw_scene", "render_scene"]

#: How boxes can be coloured.
COLOURINGS = ("cost", "truth", "none")
GREY = (0.72, 0.72, 0.72, 1.0)
Colour = tuple[float, float, float, float]


def _truth_colours(scene: Scene) -> tuple[Callable[[int], Colour], Any, Any, int] | None:
    if scene.ground_truth is None:
        return None
    from matplotlib import colormaps
    from matplotlib.colors import BoundaryNorm

    counts = np.asarray(scene.ground_truth.sum(axis=1), dtype=np.int64)
    top = int(counts.max()) if counts.size else 0
    cmap = colormaps["cividis"].resampled(max(top + 1, 2))
    norm = BoundaryNorm(np.arange(-0.5, max(top, 1) + 1.5), cmap.N)

    def colour(index: int) -> Colour:
        rgba = cmap(norm(counts[index]))
        return (float(rgba[0]), float(rgba[1]), float(rgba[2]), float(rgba[3]))

    return colour, cmap, norm, top


#: Elevation and azimuth (degrees) of the oblique view: from the door side, above.
OBLIQUE_VIEW = (28.0, -150.0)


def _draw_oblique(axes: Any, scene: Scene, colour: Callable[[int], Colour], values: DecisionValues | None) -> None:
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    detected = set(scene.detected)
    choice = values.choice if values is not None else None
    # Painted in this order, not by matplotlib's depth sort: undetected boxes (faint) first, then the
    # detected ones far to near as seen from the view below, the pick last -- never hidden behind others.
    axes.computed_zorder = False
    elevation, azimuth = np.radians(OBLIQUE_VIEW)
    eye = np.array([np.cos(elevation) * np.cos(azimuth), np.cos(elevation) * np.sin(azimuth), np.sin(elevation)])

    def painting(k: int) -> tuple[bool, bool, float]:
        box = scene.boxes[k]
        return (box.id == choice, box.id in detected, float(box.position @ eye))

    order = sorted(range(len(scene.boxes)), key=painting)
    for index in order:
        box = scene.boxes[index]
        corners = box_corners(box)
        faces = [[corners[k] for k in face] for face in BOX_FACES]
        is_detected = box.id in detected
        chosen = box.id == choice
        axes.add_collection3d(
            Poly3DCollection(
                faces,
                facecolors=[colour(index)],
                edgecolors=HIGHLIGHT if chosen else ("black" if is_detected else (0.3, 0.3, 0.3, 0.4)),
                linewidths=2.6 if chosen else (1.0 if is_detected else 0.4),
                alpha=0.95 if is_detected else 0.25,
            )
        )
    if choice is not None and choice in scene.box_ids:
        box = scene.box(choice)
        top = box.position + np.array([0.0, 0.0, float(box.size.max()) / 2.0 + 0.08])
        axes.text(
            *top, f"pick: {drawn_id(choice)}", color=HIGHLIGHT, fontsize=LABEL_POINTS + 1, fontweight="bold", zorder=30
        )
    all_corners = np.concatenate([box_corners(box) for box in scene.boxes])
    low, high = all_corners.min(axis=0), all_corners.max(axis=0)
    low[2] = 0.0
    axes.set_xlim(low[0] - 0.05, high[0] + 0.05)
    axes.set_ylim(low[1] - 0.05, high[1] + 0.05)
    axes.set_zlim(0.0, high[2] + 0.05)
    axes.set_box_aspect(tuple(np.maximum(high - low + 0.1, 0.2)), zoom=1.15)
    for name, axis in (("x (into container, m)", "x"), ("y (m)", "y"), ("z (m)", "z")):
        getattr(axes, f"set_{axis}label")(name, fontsize=LABEL_POINTS, labelpad=-4)
    axes.tick_params(labelsize=LABEL_POINTS - 1, pad=0)
    axes.view_init(*OBLIQUE_VIEW)  # from the door side
    axes.set_title("oblique view (outlined: detected)", fontsize=LABEL_POINTS + 2)


def _cloud_image(
    scene: Scene, camera: Camera, point_labels: np.ndarray | None, colour: Callable[[int], Colour] | None
) -> np.ndarray:
    width, height = (camera.width + 1) // 2, (camera.height + 1) // 2  # half resolution: no gaps between points
    image = np.ones((height, width, 4))
    points = scene.points
    if not len(points):
        return image
    pixels, depth = camera.project(points)
    pixels = pixels / 2.0
    with np.errstate(invalid="ignore"):
        columns = np.round(np.nan_to_num(pixels[:, 0], nan=-1.0)).astype(np.int64)
        rows = np.round(np.nan_to_num(pixels[:, 1], nan=-1.0)).astype(np.int64)
    inside = (depth > 0) & (columns >= 0) & (columns < width) & (rows >= 0) & (rows < height)
    if not inside.any():
        return image
    near, far = float(depth[inside].min()), float(depth[inside].max())
    shade = 1.0 - 0.5 * (depth - near) / max(far - near, 1e-9)
    colours = np.ones((len(points), 4))
    colours[:, :3] = (0.35 + 0.45 * (1.0 - shade))[:, None]
    if point_labels is not None and colour is not None:
        boxes = point_labels >= 0
        palette = np.array([colour(k) for k in range(len(scene.boxes))]).reshape(-1, 4)
        colours[boxes] = palette[point_labels[boxes]]
    order = np.argsort(-depth)
    order = order[inside[order]]
    image[rows[order], columns[order]] = colours[order]
    return image


def _crop(axes: Any, scene: Scene, camera: Camera) -> None:
    """Limit the sensor view to what the cloud and the boxes cover (no empty canvas)."""
    corners = np.concatenate([box_corners(box) for box in scene.boxes])
    pixels, depth = camera.project(corners)
    seen = pixels[(depth > 0) & np.all(np.isfinite(pixels), axis=1)]
    if not len(seen):
        return
    low = np.clip(seen.min(axis=0) - 12, 0, [camera.width, camera.height])
    high = np.clip(seen.max(axis=0) + 12, 0, [camera.width, camera.height])
    if np.all(high - low > 8):
        axes.set_xlim(low[0], high[0])
        axes.set_ylim(high[1], low[1])


def _draw_sensor(
    axes: Any,
    scene: Scene,
    camera: Camera,
    colour: Callable[[int], Colour],
    values: DecisionValues | None,
    point_labels: np.ndarray | None,
    overlay_all: bool,
) -> dict[str, np.ndarray]:
    """The cloud as the sensor saw it with the boxes' outlines over it; returns each box's centre in pixels."""
    from matplotlib.patches import Polygon

    image = _cloud_image(scene, camera, point_labels, colour if overlay_all else None)
    axes.imshow(image, interpolation="nearest", extent=(0, 2 * image.shape[1], 2 * image.shape[0], 0))
    detected = set(scene.detected)
    choice = values.choice if values is not None else None
    shown = [k for k, box in enumerate(scene.boxes) if box.id in detected or (overlay_all and point_labels is None)]
    centres: dict[str, np.ndarray] = {}
    depths = {k: float(camera.project(scene.boxes[k].position)[1][0]) for k in shown}
    for k in sorted(shown, key=lambda k: -depths[k]):  # far boxes first
        box = scene.boxes[k]
        pixels, depth = camera.project(box_corners(box))
        if np.any(depth <= 0):
            continue
        hull = convex_hull_2d(pixels)
        chosen = box.id == choice
        axes.add_patch(
            Polygon(
                hull,
                closed=True,
                facecolor=colour(k),
                alpha=0.8 if box.id in detected else 0.5,
                edgecolor=HIGHLIGHT if chosen else "black",
                linewidth=2.8 if chosen else (0.9 if box.id in detected else 0.3),
                zorder=5 if chosen else 3,
            )
        )
        if box.id in detected:
            centres[box.id] = camera.project(box.position)[0][0]
    _crop(axes, scene, camera)
    axes.set_xticks([])
    axes.set_yticks([])
    return centres


def _draw_arrows(axes: Any, centres: dict[str, np.ndarray], values: DecisionValues, threshold: float) -> int:
    drawn = 0
    for supporter, supported, probability in values.arrows(threshold):
        if supporter not in centres or supported not in centres:
            continue
        axes.annotate(
            "",
            xy=tuple(centres[supported]),
            xytext=tuple(centres[supporter]),
            arrowprops={
                "arrowstyle": "-|>",
                "color": ARROW,
                "lw": arrow_width(probability, threshold),
                "alpha": 0.9,
                "shrinkA": 4,
                "shrinkB": 4,
                "mutation_scale": 10,
            },
            zorder=10,
        )
        drawn += 1
    return drawn


def draw_scene(
    scene: Scene,
    *,
    values: DecisionValues | None = None,
    colour: str = "cost",
    camera: Camera | None = None,
    point_labels: np.ndarray | None = None,
    threshold: float = 0.5,
    arrows: bool = False,
    title: str | None = None,
) -> Any:
    """The picture of ``scene`` as a :class:`matplotlib.figure.Figure` (pyplot-free).

    Parameters
    ----------
    scene : Scene
    values : DecisionValues, optional
        The decision to show (its boxes must be boxes of the scene).
    colour : {"cost", "truth", "none"}
        Colour detected boxes by expected cost (needs ``values``), every box by the number of
        boxes it supports in the ground truth (needs one), or grey.
    camera : Camera, optional
        The sensor (default: the simulator's default sensor at the door).
    point_labels : numpy.ndarray, optional
        Box index of each cloud point (simulated scenes), to colour the cloud by ground truth.
    threshold : float
        Smallest support probability drawn as an arrow (with ``arrows``).
    arrows : bool
        Draw support arrows from ``values.probabilities``.
    title : str, optional

    Returns
    -------
    matplotlib.figure.Figure

    Raises
    ------
    InvalidArgument
        An unknown colouring, one without its data, a threshold outside [0, 1], or values
        whose boxes are not in the scene.
    """
    from unstack.plotting import figure as new_figure

    if colour not in COLOURINGS:
        raise InvalidArgument(f"colour must be one of {', '.join(COLOURINGS)}, got {colour!r}")
    threshold = check_threshold(threshold)
    if not scene.boxes:
        raise InvalidArgument(f"{scene.source}: the scene has no boxes to draw")
    if values is not None:
        values.check_boxes(scene.box_ids, scene.source)
    if colour == "cost" and values is None:
        raise InvalidArgument("colouring by expected cost needs a decision")
    truth = _truth_colours(scene)
    if colour == "truth" and truth is None:
        raise InvalidArgument(f"{scene.source}: the scene has no ground truth to colour by")
    camera = camera or Camera()
    costs = CostColours(values) if values is not None else None
    ids = scene.box_ids

    def paint(index: int) -> Colour:
        if colour == "cost" and costs is not None and ids[index] in costs.values.objects:
            return costs.of(ids[index])
        if colour == "truth" and truth is not None:
            return truth[0](index)
        return GREY

    n_ranked = len(values.objects) if values is not None else 0
    height = max(5.2, 0.165 * n_ranked + 1.4)
    ratios = [1.0, 1.15] + ([0.45] if values is not None else []) + [0.035]
    drawn = new_figure(figsize=(sum(ratios) * 5.4, height))
    grid = drawn.add_gridspec(1, len(ratios), width_ratios=ratios, left=0.01, right=0.96, top=0.9, bottom=0.09)
    grid.update(wspace=0.2)
    oblique = drawn.add_subplot(grid[0, 0], projection="3d")
    sensor = drawn.add_subplot(grid[0, 1])
    bar_axes = drawn.add_subplot(grid[0, len(ratios) - 1])
    _draw_oblique(oblique, scene, paint, values)
    centres = _draw_sensor(sensor, scene, camera, paint, values, point_labels, colour == "truth")
    sensor_title = f"sensor view ({len(scene.points):,} points)"
    if colour == "cost" and costs is not None:
        costs.colour_bar(drawn, bar_axes)
    elif colour == "truth" and truth is not None:
        from matplotlib.cm import ScalarMappable

        _, cmap, norm, top = truth
        bar = drawn.colorbar(ScalarMappable(norm=norm, cmap=cmap), cax=bar_axes, ticks=range(max(top, 1) + 1))
        bar.set_label("boxes supported (ground truth)", fontsize=LABEL_POINTS + 1)
        bar.ax.tick_params(labelsize=LABEL_POINTS)
    else:
        bar_axes.set_axis_off()
    if values is not None:
        ranking = drawn.add_subplot(grid[0, 2])
        draw_ranking(ranking, values, costs or CostColours(values))
        if arrows:
            count = _draw_arrows(sensor, centres, values, threshold)
            sensor_title += f"; {counted(count, 'support arrow')}"
            arrow_legend(sensor, threshold, f"P(X supports Y) ≥ {threshold:g}")
    sensor.set_title(sensor_title, fontsize=LABEL_POINTS + 2)
    if title:
        drawn.suptitle(title, fontsize=LABEL_POINTS + 4)
    drawn.canvas.draw()  # the layout is final: labels are placed on it
    order = sorted(centres, key=lambda box: (box != (values.choice if values else None), box))
    if values is not None:
        texts = [box_label(values, box) + ("  ← pick" if box == values.choice else "") for box in order]
    else:
        texts = list(order)
    place_labels(
        sensor,
        [(float(centres[box][0]), float(centres[box][1])) for box in order],
        texts,
        weights=["bold" if values is not None and box == values.choice else "normal" for box in order],
        colours=[HIGHLIGHT if values is not None and box == values.choice else "black" for box in order],
    )
    return drawn


def render_scene(
    scene: Scene,
    output: str | os.PathLike[str],
    *,
    dpi: int = 110,
    **options: Any,
) -> None:
    """Draw ``scene`` (see :func:`draw_scene` for ``options``) into a PNG or SVG file, atomically.

    Parameters
    ----------
    scene : Scene
    output : path
        ``.png`` or ``.svg`` (the suffix says which).
    dpi : int
        Resolution of a PNG (dots per inch).
    **options
        As for :func:`draw_scene`.
    """
    from unstack.atomic import atomic_save_figure, check_output_path

    check_output_path(output)
    atomic_save_figure(draw_scene(scene, **options), output, dpi=dpi, bbox_inches="tight", pad_inches=0.08)
