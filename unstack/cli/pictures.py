"""``unstack render`` and ``unstack view``: pictures of a decision, drawn by :mod:`unstack.pictures`.

The commands read the files and hand them to :mod:`unstack.picture_inputs` (the decision's
numbers, stored or made now, and the sensor's camera) and to :mod:`unstack.pictures`.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import click

from unstack.checks import counted
from unstack.cli.main import _warn, model_option
from unstack.cli.progress import still_working
from unstack.errors import UnstackError
from unstack.picture_inputs import decision_values, scene_camera
from unstack.pictures.render import COLOURINGS
from unstack.pictures.view import MAX_VIEW_POINTS

__all__ = ["render", "view"]

DECISION_HELP = "A stored unstack.decision/1 file to show instead of deciding (its boxes must be in the scene)."


def _load(file: str) -> tuple[Any, Path]:
    """A scene or supports file and its folder (for a simulated scene's per-point labels)."""
    from unstack.jsonio import read_document, validate_document
    from unstack.scene import Scene
    from unstack.supports import Supports

    document = read_document(file)
    if validate_document(document, ["unstack.supports/1", "unstack.scene/1"]) == "unstack.scene/1":
        from unstack.understanding.plausibility import scene_warnings

        scene = Scene.from_document(document)
        for warning in scene_warnings(scene):  # what decide would say about the scene
            _warn(warning)
        return scene, document.base_dir
    return Supports.from_document(document), document.base_dir


#: The longest title drawn (characters, one line): a longer one would stretch the picture.
MAX_TITLE = 200


def _stdin_once(*names: str | None) -> None:
    """Refuse standard input (``-``) named for two inputs: it can be read once."""
    if [name for name in names if name == "-"][1:]:
        raise UnstackError("-: standard input can be read once; it is named for two inputs: give one of them as a file")


def _check_title(title: str | None) -> None:
    if title is not None and (len(title) > MAX_TITLE or "\n" in title):
        raise UnstackError(f"--title: expected one line of at most {MAX_TITLE} characters, got {len(title)}")


def _check_suffix(output: str, suffixes: tuple[str, ...]) -> None:
    from unstack.atomic import check_output_path

    if Path(output).suffix.lower() not in suffixes:
        raise UnstackError(f"{output}: expected a {' or '.join(suffixes)} output file")
    check_output_path(output)


@click.command()
@click.argument("file", type=str)
@click.option("-o", "--output", required=True, type=click.Path(dir_okay=False), help="PNG or SVG file to write.")
@click.option(
    "--decision", "decision_file", type=click.Path(dir_okay=False, allow_dash=True), default=None, help=DECISION_HELP
)
@click.option("--colour", "--color", "colour", type=click.Choice(list(COLOURINGS)), default=None,
              help="Colour boxes by expected cost (the default for a scene with detected boxes), by the ground "
              "truth (boxes each supports; no model needed), or grey.")  # fmt: skip
@click.option("--probabilities", "arrows", is_flag=True,
              help="Draw support arrows: P(X supports Y | consistent) >= --threshold (always drawn for a supports "
              "file).")  # fmt: skip
@click.option("--threshold", type=float, default=0.5, show_default=True, help="Smallest probability drawn as an arrow.")
@click.option("--plan", "with_plan", is_flag=True, help="Number the boxes in unloading order (decide, remove, repeat).")
@model_option
@click.option("--seed", type=click.IntRange(min=0), default=0, show_default=True, help="Seed of sampled decisions.")
@click.option("--title", default=None, help="Title of the picture (default: the file name).")
@click.option("--dpi", type=click.IntRange(20, 600), default=110, show_default=True, help="Resolution of a PNG.")
def render(
    file: str,
    output: str,
    decision_file: str | None,
    colour: str | None,
    arrows: bool,
    threshold: float,
    with_plan: bool,
    model: str | None,
    seed: int,
    title: str | None,
    dpi: int,
) -> None:
    """Draw the decision on a scene: oblique view, sensor view and the ranking of expected costs.

    FILE is an unstack.scene/1 file (boxes coloured by expected cost, the pick outlined) or
    an unstack.supports/1 file (drawn as a support graph: supporters below what they support).
    """
    import unstack
    from unstack.pictures.camera import point_box_labels
    from unstack.pictures.values import check_threshold

    _check_suffix(output, (".png", ".svg"))
    _check_title(title)
    _stdin_once(file, decision_file)
    check_threshold(threshold)
    loaded, base_dir = _load(file)
    title = title or Path(file).name
    if isinstance(loaded, unstack.Supports):
        if colour in ("truth", "none"):
            raise UnstackError(f"{file}: a supports file has no ground truth or geometry; it is coloured by cost")
        with still_working("deciding"):
            values = decision_values(loaded, decision_file, with_plan=with_plan, model=model, seed=seed)
        for warning in values.warnings:
            _warn(warning)
        from unstack.pictures.graph import render_support_graph

        render_support_graph(values, output, threshold=threshold, title=title, dpi=dpi)
        click.echo(f"{output}: support graph of {counted(len(values.objects), 'box', 'boxes')}; pick {values.choice}")
        return
    scene = loaded
    camera = scene_camera(scene)  # the scene's settings are checked before any decision
    colour = colour or "cost"  # a scene always has detected boxes to decide on
    needs_decision = colour == "cost" or arrows or with_plan or decision_file is not None
    with still_working("deciding"):
        values = (
            decision_values(scene, decision_file, with_plan=with_plan, model=model, seed=seed)
            if needs_decision
            else None
        )
    for warning in values.warnings if values is not None else ():
        _warn(warning)
    from unstack.pictures.render import render_scene

    with still_working("drawing"):
        render_scene(
            scene,
            output,
            values=values,
            colour=colour,
            camera=camera,
            point_labels=point_box_labels(scene, base_dir),
            threshold=threshold,
            arrows=arrows,
            title=title,
            dpi=dpi,
        )
    pick = f"; pick {values.choice}" if values is not None else ""
    click.echo(f"{output}: {counted(len(scene.boxes), 'box', 'boxes')}, {len(scene.detected)} detected{pick}")


@click.command()
@click.argument("file", type=str)
@click.option("-o", "--output", required=True, type=click.Path(dir_okay=False), help="HTML file to write.")
@click.option(
    "--decision", "decision_file", type=click.Path(dir_okay=False, allow_dash=True), default=None, help=DECISION_HELP
)
@click.option("--plan", "with_plan", is_flag=True, help="Add a slider through the unloading order.")
@model_option
@click.option("--seed", type=click.IntRange(min=0), default=0, show_default=True,
              help="Seed of sampled decisions and of the cloud subset.")  # fmt: skip
@click.option("--max-points", type=click.IntRange(min=0, max=MAX_VIEW_POINTS), default=20_000, show_default=True,
              help=f"Cloud points shown (a random subset; at most {MAX_VIEW_POINTS:,}: a page of about 60 MB).",
              )  # fmt: skip
@click.option("--title", default=None, help="Title of the page (default: the file name).")
def view(
    file: str,
    output: str,
    decision_file: str | None,
    with_plan: bool,
    model: str | None,
    seed: int,
    max_points: int,
    title: str | None,
) -> None:
    """Write an interactive 3D page of a scene: one HTML file that needs no network.

    Boxes are coloured by expected cost; hover a box for its id, EC and strongest support
    relations; --plan adds a slider that takes the boxes away in unloading order.
    """
    import unstack

    _check_suffix(output, (".html", ".htm"))
    _check_title(title)
    _stdin_once(file, decision_file)
    loaded, _ = _load(file)
    if isinstance(loaded, unstack.Supports):
        raise UnstackError(f"{file}: a supports file has no geometry to show in 3D; unstack render draws its graph")
    with still_working("deciding"):
        values = decision_values(loaded, decision_file, with_plan=with_plan, model=model, seed=seed)
    for warning in values.warnings:
        _warn(warning)
    from unstack.pictures.view import write_view

    with still_working("writing the page"):
        size = write_view(
            loaded, output, values=values, max_points=max_points, seed=seed, title=title or Path(file).name
        )
    pick = f"; pick {values.choice}" if values is not None else ""
    click.echo(
        f"{output}: {counted(len(loaded.boxes), 'box', 'boxes')}, {len(loaded.detected)} detected{pick}; "
        f"{size / 1e6:.1f} MB"
    )
