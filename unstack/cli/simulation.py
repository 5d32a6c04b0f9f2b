"""``unstack simulate``: simulated data sets of piles (``unstack render`` is in :mod:`unstack.cli.pictures`)."""

from __future__ import annotations

import re

import click

from unstack.cli.options import scheduler_option, setting
from unstack.errors import InvalidArgument, UnstackError
from unstack.parameters import MAX_CONFIGS, MAX_JOBS
from unstack.sim.settings import FAMILIES, MIN_PILE_BOXES, SIZE_SETS, check_setting

__all__ = ["parse_box_range", "simulate"]

BOX_RANGE = re.compile(r"^\s*(-?\d+)\s*(?:-\s*(-?\d+))?\s*$")


def parse_box_range(text: str) -> tuple[int, int]:
    """``"30-40"`` -> ``(30, 40)``; ``"12"`` -> ``(12, 12)``.

    Examples
    --------
    >>> parse_box_range("30-40")
    (30, 40)
    """
    match = BOX_RANGE.match(text)
    if not match:
        raise UnstackError(f"--boxes: expected COUNT or LOW-HIGH (for example 30-40), got {text!r}")
    low = int(match.group(1))
    high = int(match.group(2)) if match.group(2) is not None else low
    if low > high:
        raise UnstackError(f"--boxes: the range {text.strip()} is reversed; expected LOW-HIGH with LOW <= HIGH")
    if low < MIN_PILE_BOXES:
        raise UnstackError(
            f"--boxes: expected at least {MIN_PILE_BOXES} boxes a pile (one box supports nothing), got {text.strip()!r}"
        )
    return low, high


@click.command()
@click.option("--configs", type=click.IntRange(1, MAX_CONFIGS), default=10, show_default=True,
              help="Configurations in the data set.")  # fmt: skip
@click.option("--family", type=click.Choice(list(FAMILIES)), default="dropped", show_default=True,
              help="Pile family: " + "; ".join(f"{name}: {text}" for name, text in FAMILIES.items())
              + ". --boxes, --sizes, --depth and --width override the family's values.")  # fmt: skip
@click.option("--boxes", default=None, help="Boxes per configuration: COUNT or LOW-HIGH (default: the family's).")
@click.option("--sizes", type=click.Choice(list(SIZE_SETS)), default=None,
              help="Box size set (default: the family's).")  # fmt: skip
@click.option("--seed", type=click.IntRange(min=0), default=0, show_default=True, help="Seed of the data set.")
@click.option("--out", "out", required=True, type=click.Path(), help="Folder of the data set (created; resumable).")
@click.option("--jobs", type=click.IntRange(1, MAX_JOBS), default=1, show_default=True,
              help="Worker processes on this machine.")  # fmt: skip
@scheduler_option("configurations")
@click.option("--depth", type=setting("Container.depth", float), default=None,
              help="Container section depth along x (m; default: the family's).")  # fmt: skip
@click.option("--width", type=setting("Container.width", float), default=None,
              help="Container section width along y (m); narrower sections stack the boxes higher.")  # fmt: skip
@click.option("--horizon", type=setting("GroundTruthSettings.horizon", float), default=1.0, show_default=True,
              help="Seconds simulated after each removal (0.001 to 10).")  # fmt: skip
@click.option("--noise/--no-noise", default=False, show_default=True, help="Kinect-like depth noise.")
@click.option("--resolution", default="640x480", show_default=True, help="Sensor image size WIDTHxHEIGHT.")
@click.option("--min-pixels", type=setting("SensorSettings.min_pixels", int), default=50, show_default=True,
              help="Visible pixels that make a box detectable (at least 1).")  # fmt: skip
@click.option("--viewpoint-jitter", type=setting("SensorSettings.position_jitter", float), default=0.0,
              show_default=True,
              help="Move the sensor of each configuration by up to this much per axis (m, 0 to 1).")  # fmt: skip
def simulate(
    configs: int,
    family: str,
    boxes: str | None,
    sizes: str | None,
    seed: int,
    out: str,
    jobs: int,
    scheduler: str | None,
    depth: float | None,
    width: float | None,
    horizon: float,
    noise: bool,
    resolution: str,
    min_pixels: int,
    viewpoint_jitter: float,
) -> None:
    """Simulate piles of boxes in a container: one unstack.scene/1 file per configuration.

    Each configuration is a settled pile with its ground-truth support matrix (by removal),
    the raw removal responses, and the range sensor's point cloud. Re-running the same
    command finishes an interrupted data set.
    """
    from dataclasses import replace

    from unstack.sim.dataset import simulate_dataset
    from unstack.sim.settings import Container, GroundTruthSettings, SensorSettings, family_settings

    base = family_settings(family)
    depth = base.container.depth if depth is None else depth
    width = base.container.width if width is None else width
    match = re.fullmatch(r"(\d+)x(\d+)", resolution.strip())
    if not match:
        raise UnstackError(f"--resolution: expected WIDTHxHEIGHT in pixels (for example 640x480), got {resolution!r}")
    try:
        pixels = [
            check_setting(int(text), f"SensorSettings.{side}")
            for text, side in zip(match.groups(), ("width", "height"), strict=True)
        ]
    except InvalidArgument as error:
        raise UnstackError(f"--resolution: {error} in {resolution!r}") from None
    if seed < 0:
        raise UnstackError(f"--seed must be a non-negative integer, got {seed}")
    sensor = replace(
        SensorSettings(),
        width=pixels[0],
        height=pixels[1],
        noise=noise,
        min_pixels=min_pixels,
        position_jitter=viewpoint_jitter,
    )
    settings = replace(
        base,
        boxes=base.boxes if boxes is None else parse_box_range(boxes),
        sizes=base.sizes if sizes is None else sizes,
        container=Container(depth=depth, width=width, height=base.container.height),
        ground_truth=GroundTruthSettings(horizon=horizon),
        sensor=sensor,
    )
    from unstack.cli.progress import progress_bar

    with progress_bar("simulating") as report:
        summary = simulate_dataset(
            out, settings, configs=configs, seed=seed, jobs=jobs, scheduler=scheduler, progress=report
        )
    from unstack.cli.text import counted
    from unstack.dataset_folders import read_manifest

    statistics = (read_manifest(summary.folder) or {}).get("statistics", {})
    wanted = summary.made + summary.skipped  # the folder may hold more than this run asked for
    asked = "" if summary.finished == wanted else f", of the {wanted} asked for"
    click.echo(
        f"{summary.folder}: {counted(summary.finished, 'configuration')} "
        f"({summary.made} made, {summary.skipped} already there{asked}) "
        f"in {summary.seconds:.1f} s; {statistics.get('support_relations', 0)} support relations among "
        f"{statistics.get('ordered_pairs', 0)} ordered pairs; of {statistics.get('transitivity_premises', 0)} "
        f"chains x supports y supports z, {100 * statistics.get('transitivity_violated_share', 0.0):.1f} % do not "
        "label x supporting z (removal labels are not transitive: a box on two others survives either's removal)"
    )
