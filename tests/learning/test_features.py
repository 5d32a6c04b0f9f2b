"""Support features (§III-A): DBAF against the direct sum, bounding boxes, the 19 numbers."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from unstack.geometry import box_corners
from unstack.learning.features import (
    FEATURE_NAMES,
    FeatureSettings,
    bounding_boxes,
    dbaf,
    interest_points,
    pair_features,
)
from unstack.scene import Box


def naive_dbaf(points: np.ndarray, queries: np.ndarray, sigma: float) -> np.ndarray:
    """Eq. 2 written out, one query at a time."""
    constant = 1.0 / (len(points) * math.sqrt((2 * math.pi * sigma) ** 3))
    return np.array([constant * np.exp(-((points - q) ** 2).sum(axis=1) / (2 * sigma**2)).sum() for q in queries])


@pytest.fixture
def cloud(rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    points = rng.uniform([0.0, -1.2, 0.0], [2.0, 1.2, 2.4], size=(5000, 3))
    queries = rng.uniform([-1.0, -2.0, -1.0], [3.0, 2.0, 3.0], size=(60, 3))
    return points, queries


@pytest.mark.parametrize("sigma", [0.05, 0.5, 1.0])
def test_direct_sum_matches_eq_2(cloud: tuple[np.ndarray, np.ndarray], sigma: float) -> None:
    points, queries = cloud
    expected = naive_dbaf(points, queries, sigma)
    assert np.allclose(dbaf(points, queries, sigma=sigma, method="direct"), expected, rtol=1e-12, atol=0)


@pytest.mark.parametrize("tolerance", [1e-3, 1e-6, 1e-9])
@pytest.mark.parametrize("sigma", [0.05, 0.5])
def test_kdtree_truncation_stays_within_its_bound(
    cloud: tuple[np.ndarray, np.ndarray], sigma: float, tolerance: float
) -> None:
    points, queries = cloud
    expected = naive_dbaf(points, queries, sigma)
    bound = tolerance / math.sqrt((2 * math.pi * sigma) ** 3)
    error = np.abs(dbaf(points, queries, sigma=sigma, method="kdtree", tolerance=tolerance) - expected)
    assert error.max() <= bound


def test_kdtree_counts_points_that_coincide_with_a_query() -> None:
    points = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.1, 0.0, 0.0]])
    queries = np.zeros((1, 3))
    expected = naive_dbaf(points, queries, 0.5)
    assert np.allclose(dbaf(points, queries, method="kdtree"), expected, rtol=1e-12)


def test_auto_picks_the_tree_only_for_narrow_kernels(cloud: tuple[np.ndarray, np.ndarray]) -> None:
    from unstack.learning.features import choose_dbaf_method

    points, _ = cloud
    assert choose_dbaf_method(points, 0.5, 1e-9) == "direct"
    assert choose_dbaf_method(points, 0.02, 1e-9) == "kdtree"


def test_an_empty_cloud_gives_zeros() -> None:
    assert dbaf(np.zeros((0, 3)), np.ones((4, 3))).tolist() == [0.0] * 4


def test_interest_points_follow_eq_3() -> None:
    points = interest_points([Box("a", [1, 1, 1], [1.0, 2.0, 3.0])], offset=0.5)[0]
    assert points.tolist() == [[1.5, 2, 3], [0.5, 2, 3], [1, 2.5, 3], [1, 1.5, 3], [1, 2, 3.5], [1, 2, 2.5]]


quaternions = st.lists(st.floats(-1, 1), min_size=4, max_size=4).filter(lambda q: np.linalg.norm(q) > 0.1)


@settings(max_examples=50, deadline=None)
@given(quaternions, st.lists(st.floats(0.1, 1.0), min_size=3, max_size=3))
def test_bounding_box_is_the_box_of_the_rotated_corners(quaternion: list[float], size: list[float]) -> None:
    box = Box("a", size, [0.3, -0.2, 0.5], np.asarray(quaternion) / np.linalg.norm(quaternion))
    corners = box_corners(box)
    expected = np.concatenate([corners.min(axis=0), corners.max(axis=0)])
    assert np.allclose(bounding_boxes([box])[0], expected, atol=1e-12)


def test_pair_features_eq_6_and_7(rng: np.random.Generator) -> None:
    boxes = [Box("a", [0.6, 0.4, 0.4], [1.0, 0.0, 0.2]), Box("b", [0.4, 0.3, 0.3], [1.1, 0.1, 0.55])]
    points = rng.uniform(0, 2, size=(300, 3))
    xy, yx = pair_features(boxes, points, [(0, 1), (1, 0)])
    assert len(FEATURE_NAMES) == 19 and xy.shape == (19,)
    assert xy[0] == yx[0] == pytest.approx(np.linalg.norm([0.1, 0.1, 0.35]))
    assert np.allclose(xy[1:7], -yx[1:7])  # F_BB(X, Y) = -F_BB(Y, X)
    assert np.array_equal(xy[7:13], yx[13:19]) and np.array_equal(xy[13:19], yx[7:13])


@pytest.mark.parametrize(
    ("arguments", "message"),
    [
        ({"sigma": 0}, r"need 0 < sigma <= 10 m, got 0"),
        ({"offset": float("inf")}, r"need 0 < offset <= 10 m, got inf"),
        ({"offset": float("nan")}, r"need 0 < offset <= 10 m, got nan"),
        ({"sigma": 1e12}, r"need 0 < sigma <= 10 m, got 1000000000000\.0"),
        ({"tolerance": 1.0}, r"need 0 < tolerance < 1, got 1\.0"),
    ],
)
def test_feature_lengths_must_be_finite_positive_and_at_most_ten_metres(
    arguments: dict[str, float], message: str
) -> None:
    from unstack.errors import UnstackError

    with pytest.raises(UnstackError, match=message):
        FeatureSettings(**arguments)  # type: ignore[arg-type]


def test_feature_settings_are_checked() -> None:
    from unstack.errors import UnstackError

    with pytest.raises(UnstackError, match="unknown DBAF method 'fft'"):
        FeatureSettings(dbaf_method="fft")
