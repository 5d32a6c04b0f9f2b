"""The cloud binned into vertical columns (unstack.understanding.cloud_columns)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from unstack.understanding.cloud_columns import CloudColumns, columns_of


def _brute_force(points: np.ndarray, low: np.ndarray, high: np.ndarray) -> np.ndarray:
    return np.flatnonzero(np.all((points[:, :2] >= low) & (points[:, :2] <= high), axis=1))


@pytest.mark.parametrize("column", [0.03, 0.1, 0.5])
@pytest.mark.parametrize("seed", range(4))
def test_points_over_a_rectangle_are_exactly_those_a_pass_over_the_cloud_finds(seed: int, column: float) -> None:
    rng = np.random.default_rng(seed)
    points = rng.uniform([-0.5, -1.2, 0.0], [2.5, 1.2, 2.0], (5000, 3))
    columns = CloudColumns(points, column)
    for _ in range(50):
        corners = np.sort(rng.uniform([-1.0, -1.5], [3.0, 1.5], (2, 2)), axis=0)
        assert columns.indices_over(corners[0], corners[1]).tolist() == _brute_force(points, *corners).tolist()


@settings(max_examples=60, deadline=None)
@given(
    st.lists(st.tuples(st.floats(-2, 2), st.floats(-2, 2), st.floats(0, 2)), max_size=40),
    st.tuples(st.floats(-3, 3), st.floats(-3, 3)),
    st.tuples(st.floats(0, 2), st.floats(0, 2)),
)
def test_a_point_on_the_rectangle_edge_is_over_it(
    points: list[tuple[float, float, float]], corner: tuple[float, float], extent: tuple[float, float]
) -> None:
    cloud = np.array(points, dtype=np.float64).reshape(-1, 3)
    low = np.array(corner)
    high = low + np.array(extent)
    if len(cloud):
        cloud[0, :2] = high  # a point exactly on the far corner
    found = CloudColumns(cloud).indices_over(low, high)
    assert found.tolist() == _brute_force(cloud, low, high).tolist()


def test_an_empty_cloud_or_an_inverted_rectangle_has_no_points() -> None:
    assert len(CloudColumns(np.zeros((0, 3))).indices_over([0, 0], [1, 1])) == 0
    columns = CloudColumns(np.array([[0.5, 0.5, 0.0]]))
    assert len(columns.indices_over([1, 1], [0, 0])) == 0
    assert columns.indices_over([0.5, 0.5], [0.5, 0.5]).tolist() == [0]


def test_shared_columns_of_the_same_cloud_are_reused_and_of_another_refused() -> None:
    rng = np.random.default_rng(3)
    points = rng.uniform(0.0, 2.0, (200, 3))
    shared = CloudColumns(points)
    assert columns_of(points, shared) is shared
    assert columns_of(points.copy(), shared) is shared  # equal values: the same cloud
    with pytest.raises(ValueError, match="the binned columns are of another point cloud"):
        columns_of(points[:100], shared)


def test_the_hidden_load_is_the_same_with_the_cloud_binned_once_or_twice() -> None:
    from unstack.scene import load_scene
    from unstack.understanding.hidden_load import hidden_load

    scene = load_scene("examples/pile5.scene.json")
    binned = CloudColumns(scene.points)
    np.testing.assert_array_equal(hidden_load(scene, columns=binned), hidden_load(scene))
