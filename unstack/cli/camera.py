"""``unstack scene``: an ``unstack.scene/1`` file from a depth camera's files and box masks.

The command reads the files (:mod:`unstack.camera.files`), calls
:func:`unstack.camera.scene_from_depth` and writes the scene (its cloud in a ``.npy`` beside
it) and, on request, the fit report; it prints the gravity tilt and every fitted box with its
residual, the duplicates left out and the masks that could not be fitted.
"""

from __future__ import annotations

import contextlib
import math
import os
import warnings
from collections.abc import Iterator
from pathlib import Path
from typing import TYPE_CHECKING

import click

from unstack.checks import MAX_BOX_EDGE, MAX_ID_LENGTH, MIN_BOX_EDGE, counted, long_id
from unstack.errors import InvalidFile, UnstackError
from unstack.jsonio import report_text

if TYPE_CHECKING:
    from unstack.camera.planes import GravityFrame

__all__ = ["scene"]


def _sizes(text: str | None) -> list[tuple[float, float, float]] | None:
    """``0.255x0.155x0.1,0.34x0.25x0.095`` -> sizes (metres)."""
    if text is None:
        return None
    sizes = []
    for item in text.split(","):
        try:
            edges = tuple(float(value) for value in item.lower().split("x"))
        except ValueError:
            where = f"{item!r} in {text!r}" if item != text else repr(text)
            raise UnstackError(f"--sizes: expected sizes like 0.4x0.3x0.3 separated by commas, got {where}") from None
        if len(edges) != 3 or not all(MIN_BOX_EDGE <= edge <= MAX_BOX_EDGE for edge in edges):
            raise UnstackError(
                f"--sizes: expected three edges of {MIN_BOX_EDGE:g}-{MAX_BOX_EDGE:g} m per size, got {item!r}"
            )
        sizes.append((edges[0], edges[1], edges[2]))
    return sizes


def _require_depth(depth_file: str | None, intrinsics_file: str | None, pose_file: str | None, what: str) -> None:
    missing = [name for name, value in (("--depth", depth_file), ("--intrinsics", intrinsics_file),
                                        ("--pose", pose_file)) if value is None]  # fmt: skip
    if missing:
        raise UnstackError(f"{what} with a depth image need {', '.join(missing)} (or give --cloud and --detections)")


def cloud_beside(target: Path) -> Path:
    """Where the cloud of the scene file ``target`` goes, beside it: its name without ``.json``, then
    ``.points.npy`` (``x.JSON`` keeps its suffix, so that it and ``x.json`` do not share one cloud).

    Examples
    --------
    >>> cloud_beside(Path("out/scene.json")).as_posix(), cloud_beside(Path("scene.JSON")).as_posix()
    ('out/scene.points.npy', 'scene.JSON.points.npy')
    """
    return target.with_name(f"{target.name.removesuffix('.json')}.points.npy")


def _check_outputs(target: Path, report_file: str | None, inputs: list[str | None]) -> None:
    """Fail before any work when the scene, its cloud or the report cannot be written, when two
    of them are one file, or when one would replace an input."""
    from unstack.atomic import check_output_path

    outputs = [target, cloud_beside(target)]
    if report_file is not None:
        outputs.append(Path(report_file))
    for output in outputs:
        check_output_path(output, inputs=inputs)
    resolved = [os.path.realpath(output) for output in outputs]
    if len(set(resolved)) != len(resolved):
        raise UnstackError(f"--report: {report_file} is also where the scene (or its cloud) goes; give another file")


@contextlib.contextmanager
def _naming(inputs: str) -> Iterator[None]:
    """Name ``inputs`` in an error of the scene's building that names no file (gravity, the fits, the
    checks of the scene built, whose source is a placeholder such as ``<cloud>``)."""
    try:
        yield
    except InvalidFile as error:
        if not error.source.startswith("<"):
            raise  # names its file already
        raise UnstackError(f"{inputs}: the scene built from them, {error.json_path}: {error.message}") from None
    except UnstackError as error:
        raise UnstackError(f"{inputs}: {error}") from None


def _mask_id(path: str) -> str:
    """A box id from a mask file's name: ``masks/mask-b07.png`` -> ``b07``."""
    stem = Path(path).stem
    for prefix in ("mask-", "mask_"):
        if stem.lower().startswith(prefix):
            return stem[len(prefix) :]
    return stem


def _door(text: str | None) -> list[float] | None:
    if not text:
        return None
    try:
        values = [float(value) for value in text.split(",")]
    except ValueError:
        values = []
    if len(values) != 3 or not any(values) or not all(math.isfinite(value) for value in values):
        raise UnstackError(f"--door: expected a direction x,y,z in the pose's frame, got {text!r}")
    largest = max(abs(value) for value in values)  # a direction: its scale does not matter, and 1e300 overflows
    return [value / largest for value in values]


def _depth_units(context: click.Context, parameter: click.Parameter, value: str | None) -> str | None:
    """``--depth-units`` checked by :func:`unstack.camera.files.depth_scale`."""
    if value is None:
        return None
    from unstack.camera.files import depth_scale
    from unstack.errors import InvalidArgument

    try:
        depth_scale(value)
    except InvalidArgument as error:
        raise click.BadParameter(str(error).removeprefix("depth units: "), context, parameter) from None
    return value


def _gravity_said(frame: GravityFrame) -> str:
    """Where gravity came from, for the table's title."""
    if frame.gravity == "pose":
        return "gravity along the pose's z, as --gravity pose asks"
    return f"gravity tilted {frame.tilt_deg:.1f} degrees from the input frame's z"


def _holds_labels(path: str) -> bool:
    """Whether a mask file holds two non-zero values or more, as a label image does."""
    from unstack.camera import load_label_masks

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return len(load_label_masks(path)) >= 2
    except UnstackError:
        return False


@click.command()
@click.argument("mask_files", nargs=-1, type=click.Path(dir_okay=False))
@click.option("--depth", "depth_file", default=None, type=click.Path(dir_okay=False),
              help="Depth image: a 16-bit PNG (mm) or a .npy of floats (m).")  # fmt: skip
@click.option("--depth-units", default=None, callback=_depth_units,
              help="Units of the depth values: mm, m, or the metres of one unit (a camera's depth scale, 0.0001 "
              "for 0.1 mm; default: mm for a PNG or a .npy of integers, m for a .npy of floats); checked.")  # fmt: skip
@click.option("--intrinsics", "intrinsics_file", default=None, type=click.Path(dir_okay=False),
              help='JSON {"fx", "fy", "cx", "cy", "width", "height"} in pixels.')  # fmt: skip
@click.option("--pose", "pose_file", default=None, type=click.Path(dir_okay=False),
              help="JSON 4 x 4 camera-to-world matrix (or an object holding one); z roughly up.")  # fmt: skip
@click.option("--cloud", "cloud_file", default=None, type=click.Path(dir_okay=False),
              help="Instead of a depth image and masks: a point cloud (.npy, .ply or .pcd), z roughly up.")  # fmt: skip
@click.option("--detections", "detections_file", default=None, type=click.Path(dir_okay=False),
              help='Instead of masks: JSON boxes [{"id", "center", "size", "yaw_deg"}] (world frame).')  # fmt: skip
@click.option("--ids", default=None,
              help="Comma-separated box ids, one per mask (default: the file names without mask-).")  # fmt: skip
@click.option("--labels", is_flag=True,
              help="MASK_FILES is one label image (PNG or .npy of whole numbers): 0 where no box is, each other "
              "value one box (ids label-VALUE, or --ids in the values' order).")  # fmt: skip
@click.option("--sizes", default=None, help="Known carton sizes, e.g. 0.255x0.155x0.1,0.34x0.25x0.095 (metres).")
@click.option("--door", default=None,
              help="Direction x,y,z (pose frame) out through the door; default: towards the camera.")  # fmt: skip
@click.option("--gravity", type=click.Choice(["planes", "pose"]), default="planes", show_default=True,
              help="planes: up from the cloud's level planes (corrects a pose tilted up to 25 degrees); pose: the "
              "pose's z is up, as a calibrated robot frame gives it (a ramp or leaning layer in view cannot turn "
              "it; the planes give the floor).")  # fmt: skip
@click.option("--out", required=True, type=click.Path(dir_okay=False), help="The scene file to write (.json).")
@click.option("--report", "report_file", default=None, type=click.Path(dir_okay=False),
              help="Also write the fit report (tilt, residuals, duplicates) as JSON.")  # fmt: skip
@click.option("--seed", type=click.IntRange(min=0), default=0, show_default=True, help="Seeds the RANSAC fits.")
def scene(
    mask_files: tuple[str, ...], depth_file: str | None, depth_units: str | None, intrinsics_file: str | None,
    pose_file: str | None, cloud_file: str | None, detections_file: str | None, ids: str | None, labels: bool,
    sizes: str | None, door: str | None, gravity: str, out: str, report_file: str | None, seed: int,
) -> None:  # fmt: skip
    """Build a scene from a depth camera's files and one mask per detected box (MASK_FILES: PNG or
    .npy, non-zero where the box is; or one label image with --labels), or from a point cloud and
    box detections.

    Gravity and the floor come from the cloud's horizontal planes (gravity from the pose's z with
    --gravity pose); each box from its mask's top face (or front face) matched to the known
    sizes, or from its detection levelled in the gravity frame. Decide on the result with
    ``unstack decide OUT``.
    """
    from rich.console import Console

    from unstack.atomic import atomic_write_text
    from unstack.camera import load_depth, load_intrinsics, load_label_masks, load_mask, load_pose, scene_from_depth
    from unstack.camera.files import without_line_labels
    from unstack.cli.text import number_table

    known = _sizes(sizes)
    target = Path(out)
    if target.suffix.lower() != ".json":
        raise UnstackError(f"--out: expected a .json file name, got {out!r}")
    _check_outputs(target, report_file, [*mask_files, depth_file, intrinsics_file, pose_file, cloud_file,
                                         detections_file])  # fmt: skip
    direction = _door(door)
    if labels and (detections_file is not None or cloud_file is not None or len(mask_files) != 1):
        extra = "".join(f" and {name}" for name, value in (("--detections", detections_file), ("--cloud", cloud_file))
                        if value)  # fmt: skip
        raise UnstackError(f"--labels reads one label image and a depth image; got {len(mask_files)} mask files{extra}")
    if detections_file is not None:  # boxes a detector found: the cloud, or the depth image's points, gives gravity
        if mask_files:
            raise UnstackError("give masks or --detections, not both")
        unused = [name for name, value in (("--sizes", sizes), ("--ids", ids)) if value is not None]
        if cloud_file is not None and depth_units is not None:
            unused.append("--depth-units")
        if unused:
            raise UnstackError(
                f"{' and '.join(unused)} apply to mask files and a depth image; the detections give each box's id "
                "and size, and a cloud is in metres"
            )
        from unstack.camera import depth_points, load_cloud, load_detections, scene_from_cloud

        if cloud_file is not None:
            if depth_file or intrinsics_file:
                named = (("--depth", depth_file), ("--intrinsics", intrinsics_file))
                given = " and ".join(name for name, value in named if value)
                raise UnstackError(f"{given}: for a depth image, not for --cloud (a cloud takes --pose alone)")
            cloud = load_cloud(cloud_file)
            if pose_file is not None:
                pose = load_pose(pose_file)
                cloud = cloud @ pose[:3, :3].T + pose[:3, 3]
        else:
            _require_depth(depth_file, intrinsics_file, pose_file, "--detections")
            assert depth_file is not None and intrinsics_file is not None and pose_file is not None
            cloud = depth_points(load_depth(depth_file, units=depth_units), load_intrinsics(intrinsics_file),
                                 load_pose(pose_file))  # fmt: skip
        with _naming(f"{cloud_file or f'{depth_file} seen from {pose_file}'} with {detections_file}"):
            built = scene_from_cloud(
                cloud, load_detections(detections_file), door=direction, seed=seed, gravity=gravity
            )
    elif cloud_file is not None:
        raise UnstackError("--cloud needs --detections: the boxes a 3-D detector found in the cloud")
    else:
        _require_depth(depth_file, intrinsics_file, pose_file, "mask files")
        if not mask_files:
            raise UnstackError("give one mask file per detected box, or --detections")
        assert depth_file is not None and intrinsics_file is not None and pose_file is not None
        # a label image is read whole at the depth image's size (refused first when it is another),
        # its lines kept until the ids are matched to every value the file holds
        depth = load_depth(depth_file, units=depth_units) if labels else None
        label_masks = (
            load_label_masks(mask_files[0], None if depth is None else depth.shape, lines=True) if labels else {}
        )
        sources = [f"{mask_files[0]} label {value}" for value in label_masks] if labels else list(mask_files)
        default = [f"label-{value}" for value in label_masks] if labels else [_mask_id(p) for p in mask_files]
        names = [name.strip() for name in ids.split(",")] if ids is not None else default
        given = f"{len(sources)} labels in {mask_files[0]}" if labels else f"{len(mask_files)} masks"
        if len(names) != len(sources):
            raise UnstackError(f"--ids names {len(names)} boxes but {given} were given")
        if ids is not None and not all(names):
            raise UnstackError(f"--ids: expected {len(sources)} non-empty box ids separated by commas, got {ids!r}")
        for path, name in zip(sources, names, strict=True):
            if len(name) > MAX_ID_LENGTH:  # before any fitting: an id no scene holds
                raise UnstackError(f"{'--ids' if ids is not None else path}: {long_id(name)}")
        unnamed = [path for path, name in zip(sources, names, strict=True) if not name]
        if unnamed:
            raise UnstackError(
                f"{unnamed[0]}: the file name gives an empty box id; rename it (mask-ID.png) or give --ids"
            )
        repeated = sorted({path for path in mask_files if mask_files.count(path) > 1})
        if repeated:
            raise UnstackError(f"{repeated[0]}: the same mask file is given twice")
        twice = next((name for name in names if names.count(name) > 1), None)
        if twice is not None:
            named_by = [path for path, name in zip(sources, names, strict=True) if name == twice]
            where = "--ids" if ids is not None else f"{named_by[0]} and {named_by[1]}"
            raise UnstackError(f"{where}: the box id {twice!r} is given to two boxes; ids must differ")
        depth = load_depth(depth_file, units=depth_units) if depth is None else depth
        intrinsics = load_intrinsics(intrinsics_file)
        if (intrinsics.width, intrinsics.height) != (depth.shape[1], depth.shape[0]):
            pixels = f"{depth.shape[1]} x {depth.shape[0]} pixels ({depth_file})"
            given = f"{intrinsics.width} x {intrinsics.height}"
            raise InvalidFile(intrinsics_file, "$.width", f"expected the depth image's {pixels}, got {given}")
        pose = load_pose(pose_file)
        if labels:  # the lines left out, named by their ids
            id_of = dict(zip(label_masks, names, strict=True))
            label_masks = without_line_labels(label_masks, mask_files[0], id_of)
            names = [id_of[value] for value in label_masks]
        masks = list(label_masks.values()) if labels else [load_mask(path, depth.shape) for path in mask_files]
        with _naming(f"{depth_file} seen from {pose_file}"):
            try:
                built = scene_from_depth(
                    depth,
                    intrinsics,
                    pose,
                    masks,
                    ids=names,
                    known_sizes=known,
                    door=direction,
                    seed=seed,
                    gravity=gravity,
                )
            except UnstackError as error:
                if (
                    len(mask_files) == 1
                    and not labels
                    and str(error).startswith("no box could be fitted")
                    and _holds_labels(mask_files[0])
                ):
                    hint = "one mask file given: if it is a label image, a value per box, give --labels"
                    raise UnstackError(f"{error} ({hint})") from None
                raise
    built.scene.save(target, points_file=cloud_beside(target).name)
    if report_file is not None:
        atomic_write_text(Path(report_file), report_text(built.report()))
    console = Console()
    table = number_table(
        f"{counted(len(built.scene.boxes), 'box', 'boxes')} ({_gravity_said(built.frame)})",
        ("box", "face", "size (m)", "position (m)", "residual (mm)", "face seen"),
    )
    fits = {item.box.id: item for item in built.fitted}
    for box in built.scene.boxes:
        item = fits.get(box.id)
        table.add_row(
            box.id, item.face if item else "detected", " x ".join(f"{edge:.3f}" for edge in box.size),
            ", ".join(f"{value:.3f}" for value in box.position), f"{1000 * item.residual_m:.1f}" if item else "-",
            f"{100 * item.fill:.0f} %" if item else "-",
        )  # fmt: skip
    console.print(table)
    partial = [item.box.id for item in built.fitted if item.partial]
    if partial:
        console.print(f"seen in part (the pose is placed from the part seen): {', '.join(partial)}")
    for duplicate, kept in built.duplicates.items():
        console.print(f"left out {duplicate}: its mask lies mostly inside {kept}'s (a duplicate detection)")
    for box_id, reason in built.unfitted.items():
        console.print(f"left out {box_id}: {reason}")
    from unstack.cli.main import _warn
    from unstack.scene import load_scene
    from unstack.understanding.plausibility import scene_warnings

    for warning in [*built.doubts(), *scene_warnings(load_scene(target))]:  # and what decide will say of it
        _warn(warning)
    click.echo(f"scene in {target}; decide with: unstack decide {target}")
