"""The loaders under fuzzing: JSON round trips are exact; mutated files raise only UnstackError."""

from __future__ import annotations

import contextlib
import copy
import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import unstack
from unstack.errors import UnstackError
from unstack.scene import Box, Scene
from unstack.supports import Supports

REPO = Path(__file__).resolve().parents[1]
FUZZ = settings(max_examples=120, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])

ids = st.text(min_size=1, max_size=12)


def _saved_and_loaded(original: Supports | Scene, file: Path) -> Any:
    """``original`` saved to ``file`` and loaded back, checked to be of its own type."""
    original.save(file)
    loaded = unstack.load(file)
    assert type(loaded) is type(original)
    return loaded


probability = st.floats(0.0, 1.0, allow_nan=False)


@st.composite
def supports(draw: st.DrawFn) -> Supports:
    objects = draw(st.lists(ids, min_size=1, max_size=6, unique=True))
    n = len(objects)
    matrix = np.array(draw(st.lists(probability, min_size=n * n, max_size=n * n))).reshape(n, n)
    np.fill_diagonal(matrix, 0.0)
    masses = draw(st.none() | st.lists(st.floats(1e-3, 1e3), min_size=n, max_size=n))
    return Supports(objects, matrix, masses=masses, metadata={"note": draw(st.text(max_size=20))})


@FUZZ
@given(supports())
def test_supports_round_trip_exactly(tmp_path: Path, original: Supports) -> None:
    loaded = _saved_and_loaded(original, tmp_path / "supports.json")
    assert loaded.objects == original.objects
    np.testing.assert_array_equal(loaded.probabilities, original.probabilities)
    if original.masses is None:
        assert loaded.masses is None
    else:
        np.testing.assert_array_equal(loaded.masses, original.masses)
    assert loaded.to_dict() == original.to_dict()


@st.composite
def scenes(draw: st.DrawFn) -> Scene:
    count = draw(st.integers(1, 4))
    box_ids = draw(st.lists(ids, min_size=count, max_size=count, unique=True))
    edge = st.floats(0.05, 1.0)
    boxes = [
        Box(
            box_id,
            [draw(edge), draw(edge), draw(edge)],
            [2.0 * k + draw(st.floats(-0.1, 0.1)), draw(st.floats(-1, 1)), draw(st.floats(0.1, 3))],
            mass=draw(st.none() | st.floats(0.1, 50)),
        )
        for k, box_id in enumerate(box_ids)
    ]
    points = draw(st.lists(st.tuples(*[st.floats(-5, 5)] * 3), max_size=10))
    detected = draw(st.lists(st.sampled_from(box_ids), min_size=1, unique=True))
    return Scene(boxes, points=np.array(points, dtype=np.float64).reshape(-1, 3), detected=detected)


@FUZZ
@given(scenes())
def test_scenes_round_trip_exactly(tmp_path: Path, original: Scene) -> None:
    loaded = _saved_and_loaded(original, tmp_path / "scene.json")
    assert loaded.to_dict() == original.to_dict()
    np.testing.assert_array_equal(loaded.points, original.points)


def _documents() -> list[dict[str, Any]]:
    pile5 = unstack.load_supports(REPO / "examples" / "stack5.supports.json")
    scene = json.loads((REPO / "examples" / "scene3.json").read_text())
    scene.pop("points_file", None)
    scene["points"] = [[1.0, 0.0, 0.5], [1.2, 0.1, 0.4]]
    return [
        json.loads((REPO / "examples" / "stack5.supports.json").read_text()),
        json.loads((REPO / "examples" / "evidence3.supports.json").read_text()),
        scene,
        unstack.decide(pile5).to_dict(),
        unstack.plan(pile5).to_dict(),
    ]


DOCUMENTS = _documents()
json_values = st.recursive(
    st.none() | st.booleans() | st.integers() | st.floats(allow_nan=False) | st.text(max_size=8),
    lambda children: st.lists(children, max_size=4) | st.dictionaries(st.text(max_size=6), children, max_size=4),
    max_leaves=12,
)


def _paths(value: Any, path: tuple[Any, ...] = ()) -> list[tuple[Any, ...]]:
    found = [path]
    if isinstance(value, dict):
        for key, child in value.items():
            found += _paths(child, (*path, key))
    elif isinstance(value, list):
        for index, child in enumerate(value):
            found += _paths(child, (*path, index))
    return found


@st.composite
def mutated(draw: st.DrawFn) -> str:
    document = copy.deepcopy(draw(st.sampled_from(DOCUMENTS)))
    for _ in range(draw(st.integers(1, 3))):
        paths = _paths(document)
        path = draw(st.sampled_from(paths))
        action = draw(st.sampled_from(["replace", "delete", "insert", "number"]))
        if not path:
            continue
        parent = document
        for part in path[:-1]:
            parent = parent[part]
        last = path[-1]
        if action == "replace":
            parent[last] = draw(json_values)
        elif action == "delete":
            del parent[last]
        elif action == "insert" and isinstance(parent, dict):
            parent[draw(st.text(max_size=6))] = draw(json_values)
        elif action == "number":
            parent[last] = draw(st.sampled_from([0, -1, 1e300, -1e300, 1e-300, 2**70, 0.5, 1, True, "", []]))
    text = json.dumps(document)
    if draw(st.booleans()):  # damage the text itself
        cut = draw(st.integers(0, len(text)))
        text = text[:cut] + draw(st.sampled_from(["", "]", "}", '"', "\\", "\x00", "NaN", "1e999", "[" * 80]))
    return text


@FUZZ
@given(mutated())
def test_mutated_files_raise_only_unstack_errors(tmp_path: Path, text: str) -> None:
    file = tmp_path / "mutated.json"
    file.write_text(text)
    for reader in (unstack.load, unstack.validate):
        with contextlib.suppress(UnstackError):  # anything else fails the test
            reader(file)


@pytest.mark.parametrize("tag", [[], {}, 1, None, True])
def test_a_format_tag_of_the_wrong_type(tmp_path: Path, tag: Any) -> None:
    file = tmp_path / "tag.json"
    file.write_text(json.dumps({"format": tag}))
    for reader in (unstack.load, unstack.validate):
        with pytest.raises(UnstackError, match=r"tag\.json: \$(\.format)?: "):
            reader(file)


@pytest.mark.parametrize("document", DOCUMENTS[:3], ids=["pile5", "evidence3", "scene3"])
def test_the_seeds_of_the_fuzzer_are_valid(tmp_path: Path, document: dict[str, Any]) -> None:
    file = tmp_path / "valid.json"
    file.write_text(json.dumps(document))
    unstack.validate(file)


@pytest.mark.parametrize("reader", ["load", "validate"])
def test_a_pipe_or_a_device_is_refused_without_reading_it(tmp_path: Path, reader: str) -> None:
    import os

    fifo = tmp_path / "pile.json"
    os.mkfifo(fifo)  # opening it to read would wait for a writer forever
    for path, kind in ((fifo, "a pipe"), (Path("/dev/zero"), "a device")):
        with pytest.raises(UnstackError, match=f"{path}: \\$: expected a regular file, got {kind}"):
            getattr(unstack, reader)(path)
