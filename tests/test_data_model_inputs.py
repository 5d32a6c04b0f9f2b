"""The data model keeps its own copies of what a caller hands it: the caller's arrays stay the
caller's (writeable), metadata is copied as its JSON document holds it, and nothing is saved
that unstack would refuse to read back."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest

import unstack
from unstack.errors import InvalidArgument, InvalidScene, InvalidSupports

PROBABILITIES = [[0.0, 0.2, 0.1], [0.7, 0.0, 0.3], [0.4, 0.5, 0.0]]
IDS = ["a", "b", "c"]


def _scene(points: np.ndarray, metadata: dict[str, Any] | None = None) -> unstack.Scene:
    box = unstack.Box("a", [0.4, 0.4, 0.4], [1.0, 0.0, 0.2])
    return unstack.Scene([box], points, ["a"], metadata=metadata)


def test_supports_leave_the_callers_arrays_writeable_and_unshared() -> None:
    matrix = np.array(PROBABILITIES)
    masses, heights = np.array([1.0, 2.0, 3.0]), np.array([0.2, 0.6, 1.0])
    supports = unstack.Supports(IDS, matrix, masses, heights=heights)
    assert matrix.flags.writeable and masses.flags.writeable and heights.flags.writeable
    matrix[0, 1] = 0.99
    assert supports.probabilities[0, 1] == 0.2  # the caller's change is not the supports'
    assert not supports.probabilities.flags.writeable


def test_a_scene_leaves_the_callers_cloud_writeable_and_unshared() -> None:
    cloud = np.random.default_rng(0).uniform(0.0, 1.0, size=(50, 3))
    scene = _scene(cloud)
    cloud[0] = 9.0
    assert cloud.flags.writeable and not np.array_equal(scene.points[0], cloud[0])
    assert not scene.points.flags.writeable


def test_metadata_is_a_deep_copy_in_json_types() -> None:
    given = {"nested": {"list": [1, 2]}, "number": np.float32(0.5), "count": np.int64(3), "pair": (1, 2)}
    supports = unstack.Supports(IDS, PROBABILITIES, metadata=given)
    given["nested"]["list"].append(3)
    assert supports.metadata == {"nested": {"list": [1, 2]}, "number": 0.5, "count": 3, "pair": [1, 2]}
    assert type(supports.metadata["number"]) is float and type(supports.metadata["count"]) is int


@pytest.mark.parametrize(
    "metadata, message",
    [
        ({"x": float("nan")}, r"\$\.metadata\.x: expected a finite number, got nan"),
        ({"a": {"b": [1, float("inf")]}}, r"\$\.metadata\.a\.b\[1\]: expected a finite number, got inf"),
        ({"x": object()}, r"\$\.metadata\.x: expected a JSON value \(text, a number, .*\), got object"),
        ({"a": {(1, 2): 3}}, r"\$\.metadata\.a: expected an object with string keys, got the key \(1, 2\)"),
    ],
)
@pytest.mark.parametrize("kind", ["supports", "scene"])
def test_metadata_a_file_could_not_hold_is_refused_naming_its_path(
    metadata: dict[str, Any], message: str, kind: str
) -> None:
    error = InvalidSupports if kind == "supports" else InvalidScene
    with pytest.raises(error, match=message):
        if kind == "supports":
            unstack.Supports(IDS, PROBABILITIES, metadata=metadata)
        else:
            _scene(np.zeros((1, 3)), metadata)


def test_metadata_holding_itself_is_refused_in_one_line() -> None:
    looped: dict[str, Any] = {}
    looped["self"] = looped
    with pytest.raises(InvalidSupports, match=r"\$\.metadata: expected a JSON object: nested too deeply, or holding"):
        unstack.Supports(IDS, PROBABILITIES, metadata=looped)


@pytest.mark.parametrize(
    "path, message",
    [(None, r" \(a str or path-like\), got NoneType"), (b"out.json", r" \(a str or path-like\), got bytes"),
     ("", r", got an empty one"), ("out.json/", r", got a folder's \(it ends with '/'\)")],
)  # fmt: skip
def test_saving_to_something_that_is_no_file_name_is_refused(tmp_path: Path, path: Any, message: str) -> None:
    supports = unstack.Supports(IDS, PROBABILITIES)
    target = f"{tmp_path}/{path}" if path == "out.json/" else path
    with pytest.raises(InvalidArgument, match=r"expected a file name for the output" + message):
        supports.save(target)
    assert list(tmp_path.iterdir()) == []


def test_metadata_keys_that_are_not_text_are_named() -> None:
    with pytest.raises(InvalidSupports, match=r"\$\.metadata: expected string keys, got the key 1 \(int\)"):
        unstack.Supports(IDS, PROBABILITIES, metadata={1: "x"})


def test_a_value_put_into_the_metadata_afterwards_that_json_cannot_hold_is_not_saved(tmp_path: Path) -> None:
    supports = unstack.Supports(IDS, PROBABILITIES)
    supports.metadata["late"] = float("nan")  # the dict is the caller's to change; the file is ours
    target = tmp_path / "late.json"
    with pytest.raises(
        InvalidArgument, match=r"late.json: the document holds a value JSON cannot .*nothing was written"
    ):
        supports.save(target)
    assert not target.exists() and list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("mass", [10_000.5, 1.7e308])
def test_a_mass_above_what_the_schemas_allow_is_refused_in_the_library_too(mass: float) -> None:
    with pytest.raises(InvalidSupports, match=r"\$\.masses\[0\]: expected at most 10,000 kg \(a carton; kg\?\), got "):
        unstack.Supports(IDS, PROBABILITIES, masses=[mass, 1.0, 1.0])
    with pytest.raises(InvalidScene, match=r"\$\.mass: expected at most 10,000 kg \(a carton; kg\?\), got "):
        unstack.Box("a", [0.4, 0.4, 0.4], [1.0, 0.0, 0.2], mass=mass)


@pytest.mark.parametrize(
    ("field", "values", "message"),
    [
        ("heights", [-100.0, 0.0, 0.0], r"\$\.heights\[0\]: expected a height from -1 to 100 m, got -100"),
        ("heights", [0.0, 0.0, 1e9], r"\$\.heights\[2\]: expected a height from -1 to 100 m, got 1e\+09"),
        ("hidden_load", [0.0, 1e9, 0.0], r"\$\.hidden_load\[1\]: expected at most 1,000 boxes, got 1e\+09"),
    ],
)
def test_heights_and_loads_the_schema_refuses_are_refused_in_the_library_too(
    field: str, values: list[float], message: str
) -> None:
    """What the library accepts, it saves as a file it loads again."""
    with pytest.raises(InvalidSupports, match=message):
        unstack.Supports(IDS, PROBABILITIES, **{field: values})


def test_the_librarys_bounds_on_heights_and_loads_are_the_schemas() -> None:
    from unstack.checks import HEIGHT_RANGE, REFUSED_HIDDEN_LOAD
    from unstack.jsonio import load_schema

    fields = load_schema("unstack.supports/1")["properties"]
    assert (fields["heights"]["items"]["minimum"], fields["heights"]["items"]["maximum"]) == HEIGHT_RANGE
    assert fields["hidden_load"]["items"]["maximum"] == REFUSED_HIDDEN_LOAD


def test_an_empty_file_name_is_said_to_be_empty_not_a_folder() -> None:
    from unstack.errors import InvalidFile

    with pytest.raises(InvalidFile, match=r"^'': \$: expected a file name, got an empty one$"):
        unstack.load("")


@pytest.mark.parametrize(
    ("field", "index", "value", "message"),
    [
        ("position", slice(None), np.nan, r"\$\.boxes\[13\]\.position\[0\]: expected a finite number, got nan"),
        ("orientation_xyzw", slice(None), 0.0, r"\$\.boxes\[13\]\.orientation_xyzw: expected a unit quaternion"),
        ("position", 0, 1e9, r"\$\.boxes\[13\]\.position\[0\]: expected a coordinate within 100 m"),
        ("size", 0, -0.4, r"\$\.boxes\[13\]\.size\[0\]: expected a positive number, got -0\.4"),
    ],
    ids=["not-finite", "zero-quaternion", "far-away", "negative-size"],
)
def test_a_box_changed_in_place_to_a_pose_the_scene_refuses_is_refused_where_it_is(
    examples: Path, field: str, index: Any, value: float, message: str
) -> None:
    """A box's arrays stay writeable (scipy's Rotation.apply refuses read-only ones); a zero
    quaternion, 1e9 m or a negative size put into them was decided on unchecked."""
    scene = unstack.load(examples / "pile5.scene.json")
    getattr(scene.boxes[13], field)[index] = value
    with pytest.raises(InvalidArgument, match=message + r".*\(changed in place after the scene was made\)"):
        unstack.decide(scene)


def test_a_box_resting_below_the_floor_is_named_by_its_position_not_by_the_supports_heights() -> None:
    """It was refused as '$.heights[0]', a field of the supports the caller never gave."""
    boxes = [unstack.Box("a", [0.4, 0.4, 0.4], [1.0, 0.0, -5.0]), unstack.Box("b", [0.4, 0.4, 0.4], [1.0, 0.5, 0.2])]
    with pytest.raises(InvalidScene, match=r"\$\.boxes\[0\]\.position: box 'a' rests at -5\.20 m: expected its bottom"):
        unstack.decide(unstack.Scene(boxes, np.zeros((0, 3)), ["a", "b"]))


@pytest.mark.parametrize(
    "build",
    [
        lambda masked: unstack.Supports(IDS, masked(PROBABILITIES)),
        lambda masked: unstack.Supports(IDS, PROBABILITIES, masses=masked([1.0, 2.0, 3.0])),
        lambda masked: _scene(masked([[1.0, 0.0, 0.4]])),
        lambda masked: unstack.Box("a", masked([0.4, 0.4, 0.4]), [1.0, 0.0, 0.2]),
    ],
    ids=["probabilities", "masses", "points", "size"],
)
def test_a_masked_array_is_refused_not_read_under_its_mask(build: Any) -> None:
    """numpy read the values under the mask: a masked P(b supports a) of 0.9 was decided on as 0.9."""

    def masked(values: Any) -> np.ndarray:
        array = np.asarray(values, dtype=float)
        return np.ma.masked_array(array, mask=np.eye(*array.shape, dtype=bool) if array.ndim == 2 else array < 0.5)

    with pytest.raises((InvalidSupports, InvalidScene), match="expected a plain array, got a masked array"):
        build(masked)


def test_a_boolean_matrix_is_refused_as_true_and_false_cells_are() -> None:
    """A bool array was read as 0 and 1, while [[0, np.True_], ...] was refused."""
    with pytest.raises(InvalidSupports, match=r"\$\.probabilities: expected real numbers, got dtype bool"):
        unstack.Supports(["a", "b"], np.array([[False, True], [False, False]]))
