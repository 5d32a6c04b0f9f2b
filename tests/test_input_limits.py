"""Inputs above the stated sizes are refused in one line, before they are read whole."""

from __future__ import annotations

import io
import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

import unstack
from tests.conftest import assert_one_line_error
from tests.conftest import unstack as unstack_cli
from unstack import jsonio, scene
from unstack.errors import InvalidFile, InvalidScene


def test_a_json_file_above_the_limit_is_refused_before_it_is_read(tmp_path: Path) -> None:
    huge = tmp_path / "huge.json"
    with huge.open("wb") as handle:  # a sparse file: its size is there, its bytes are not
        handle.truncate(jsonio.MAX_DOCUMENT_BYTES + 1)
    with pytest.raises(
        InvalidFile, match=r"huge.json: \$: expected a document of at most 64.0 MiB, the file has 64.0 MiB"
    ):
        unstack.load(huge)


def test_standard_input_above_the_limit_is_refused(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(jsonio, "MAX_DOCUMENT_BYTES", 64)
    monkeypatch.setattr(
        "sys.stdin", io.TextIOWrapper(io.BytesIO(b'{"format": "unstack.supports/1", ' + b" " * 100 + b"}"))
    )
    with pytest.raises(InvalidFile, match=r"<stdin>: \$: expected a document of at most 0.0 MiB; got more"):
        unstack.load("-")


def scene_with_cloud(tmp_path: Path, cloud: str) -> Path:
    document = {
        "format": "unstack.scene/1",
        "boxes": [{"id": "a", "size": [0.4, 0.4, 0.4], "position": [1.0, 0.0, 0.2], "orientation_xyzw": [0, 0, 0, 1]}],
        "detected": ["a"],
        "points_file": cloud,
    }
    path = tmp_path / "scene.json"
    path.write_text(json.dumps(document))
    return path


def test_a_npy_cloud_of_too_many_points_is_refused_from_its_header(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    np.save(tmp_path / "cloud.npy", np.zeros((11, 3)))
    monkeypatch.setattr(scene, "MAX_POINTS", 10)

    def never(*_args: object, **_kwargs: object) -> None:
        raise AssertionError("the cloud was read")

    monkeypatch.setattr(np, "load", never)
    with pytest.raises(InvalidScene, match=r"points_file: expected at most 10 points, 'cloud.npy' has 11"):
        unstack.load(scene_with_cloud(tmp_path, "cloud.npy"))


def test_a_cloud_file_above_the_byte_limit_is_refused(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    (tmp_path / "cloud.ply").write_bytes(b"ply\n" + b" " * 2000)
    monkeypatch.setattr(scene, "MAX_CLOUD_FILE_BYTES", 1024)
    with pytest.raises(InvalidScene, match=r"expected a point cloud file of at most 0 MiB, 'cloud.ply' has 0.0 MiB"):
        unstack.load(scene_with_cloud(tmp_path, "cloud.ply"))


def test_a_cloud_within_the_limits_loads(tmp_path: Path) -> None:
    np.save(tmp_path / "cloud.npy", np.random.default_rng(0).uniform(0, 1, (50, 3)))
    assert unstack.load(scene_with_cloud(tmp_path, "cloud.npy")).points.shape == (50, 3)


def test_supports_of_more_boxes_than_the_limit_are_refused_in_one_line(tmp_path: Path) -> None:
    document = {"format": "unstack.supports/1", "objects": [f"b{k}" for k in range(2001)], "probabilities": []}
    path = tmp_path / "many.json"
    path.write_text(json.dumps(document))
    with pytest.raises(InvalidFile, match=r"many.json: \$.objects: expected at most 2000 items, got 2001"):
        unstack.load(path)


def test_a_large_document_is_checked_by_the_compiled_schema_with_its_path(tmp_path: Path) -> None:
    padding = "x" * (jsonio.LARGE_DOCUMENT + 1)
    document = {"format": "unstack.supports/1", "objects": ["a", "b"], "probabilities": [[0, "high"], [0, 0]],
                "metadata": {"description": padding}}  # fmt: skip
    path = tmp_path / "large.json"
    path.write_text(json.dumps(document))
    with pytest.raises(InvalidFile, match=r"large.json: \$.probabilities\[0\]\[1\]: must be number"):
        unstack.load(path)


@pytest.mark.slow  # a subprocess
def test_the_cli_refuses_a_document_above_the_limit_with_exit_2(tmp_path: Path) -> None:
    huge = tmp_path / "huge.json"
    with huge.open("wb") as handle:
        handle.truncate(jsonio.MAX_DOCUMENT_BYTES + 1)
    for command in ("decide", "validate"):
        result = unstack_cli(command, str(huge))
        assert_one_line_error(result, "at most 64.0 MiB")


@pytest.mark.parametrize(
    ("limit", "lines"),
    [(10_000, 25), (200, 1)],
    ids=["indented-when-it-fits", "one-line-when-indented-is-too-large"],
)
def test_written_documents_stay_within_what_unstack_reads_back(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, limit: int, lines: int
) -> None:
    supports = unstack.Supports(["a", "b", "c"], [[0, 0.25, 0.5], [0.125, 0, 0.75], [0.5, 0.5, 0]])
    monkeypatch.setattr(jsonio, "MAX_DOCUMENT_BYTES", limit)
    supports.save(tmp_path / "s.json")
    text = (tmp_path / "s.json").read_text()
    assert len(text) <= limit and len(text.splitlines()) == lines
    assert unstack.load(tmp_path / "s.json").probabilities.tolist() == supports.probabilities.tolist()


def test_a_document_too_large_even_on_one_line_is_not_written(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    points = np.zeros((50, 3))
    cloud_scene = unstack.Scene([scene.Box("a", [0.4, 0.4, 0.4], [1.0, 0.0, 0.2])], points, ["a"])
    monkeypatch.setattr(jsonio, "MAX_DOCUMENT_BYTES", 200)
    with pytest.raises(
        unstack.errors.InvalidArgument,
        match=r"big.json: the JSON would be 0.0 MiB even without indentation, more than the 0.0 MiB unstack reads "
        r"back; nothing was written; save the cloud to a .npy file beside it \(points_file\)",
    ):
        cloud_scene.save(tmp_path / "big.json")
    assert list(tmp_path.iterdir()) == []
    cloud_scene.save(tmp_path / "small.json", points_file="small.npy")
    assert unstack.load(tmp_path / "small.json").points.shape == (50, 3)


def _reference_paths(value: Any, path: tuple[Any, ...] = ()) -> list[tuple[Any, ...]]:
    """Every nested value's path, depth first in document order (recursive: the oracle)."""
    children = value.items() if isinstance(value, dict) else enumerate(value) if isinstance(value, list) else ()
    return [found for key, child in children for found in [(*path, key), *_reference_paths(child, (*path, key))]]


json_values = st.recursive(
    st.none() | st.booleans() | st.integers() | st.floats(allow_nan=True, allow_infinity=True) | st.text(max_size=3),
    lambda inner: st.lists(inner, max_size=4) | st.dictionaries(st.text(max_size=3), inner, max_size=4),
    max_leaves=30,
)


@given(json_values)
def test_the_walk_of_a_document_meets_every_value_in_document_order(value: Any) -> None:
    from unstack.jsonio import _find_non_finite, _walk, too_deep

    reference = _reference_paths(value)
    assert [tuple(path) for path, _ in _walk(value)] == reference
    bad = [path for path in reference if isinstance(_get(value, path), float) and not np.isfinite(_get(value, path))]
    assert [tuple(path) for path in _find_non_finite(value, [])] == ([()] if _is_bad(value) else []) + bad
    deepest = [path for path in reference if len(path) > 2]
    assert too_deep(value, 2) == (list(deepest[0]) if deepest else None)


def _get(value: Any, path: tuple[Any, ...]) -> Any:
    for key in path:
        value = value[key]
    return value


def _is_bad(value: Any) -> bool:
    return isinstance(value, float) and not np.isfinite(value)
