"""Contact features: values on hand-made piles, the brute-force cloud shares, the extended set."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from unstack.errors import UnstackError
from unstack.learning.contact_features import CONTACT_FEATURE_NAMES, contact_features
from unstack.learning.features import FeatureSettings, feature_names, pair_features
from unstack.scene import Box


def named(row: np.ndarray) -> dict[str, float]:
    return dict(zip(CONTACT_FEATURE_NAMES, row.tolist(), strict=True))


@pytest.fixture
def stack() -> list[Box]:
    """A floor box, a box on it (shifted 0.1 m along x), and a box 1 m to the side."""
    return [
        Box("floor", [0.6, 0.4, 0.4], [1.0, 0.0, 0.2]),
        Box("top", [0.4, 0.4, 0.3], [1.1, 0.0, 0.55]),
        Box("side", [0.4, 0.4, 0.4], [1.0, 1.0, 0.2]),
    ]


def test_geometry_of_a_box_resting_on_another(stack: list[Box]) -> None:
    on, under, apart = contact_features(stack, np.zeros((0, 3)), [(0, 1), (1, 0), (0, 2)])
    assert named(on)["vertical_gap"] == pytest.approx(0.0)
    assert named(under)["vertical_gap"] == pytest.approx(-0.7)
    assert named(on)["overlap_x"] == pytest.approx(0.4) and named(on)["overlap_y"] == pytest.approx(0.4)
    assert named(on)["overlap_share_y"] == pytest.approx(1.0)
    assert named(on)["overlap_share_x"] == pytest.approx(0.16 / 0.24)
    assert named(on)["footprint_gap"] == 0.0 and named(apart)["footprint_gap"] == pytest.approx(0.6)
    assert named(apart)["overlap_share_y"] == 0.0 and named(apart)["overlap_y"] == pytest.approx(-0.6)
    assert (named(on)["height_x"], named(on)["bottom_y"]) == pytest.approx((0.4, 0.4))
    assert named(on)["pair_box_volume"] == pytest.approx(0.6 * 0.4 * 0.7)
    assert not any(named(on)[name] for name in CONTACT_FEATURE_NAMES if name.startswith(("cloud", "rise")))


def test_cloud_over_a_box_and_between_two(stack: list[Box]) -> None:
    lifted = [stack[0], Box("high", [0.4, 0.4, 0.3], [1.0, 0.0, 0.85])]  # 0.3 m above the floor box
    points = np.array([[1.0, 0.0, 0.55], [1.0, 0.0, 1.0], [3.0, 3.0, 3.0], [1.0, 0.0, 0.1]])
    row = named(contact_features(lifted, points, [(0, 1)])[0])
    assert row["cloud_between"] == pytest.approx(0.25)  # the point at z = 0.55 in the 0.3 m gap
    assert row["rise_above_x"] == pytest.approx(0.6) and row["cloud_above_x"] == pytest.approx(0.5)
    assert row["rise_above_y"] == 0.0 and row["cloud_above_y"] == 0.0
    assert row["cloud_in_pair_box"] == pytest.approx(0.75)


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_cloud_shares_match_a_brute_force_count(seed: int) -> None:
    rng = np.random.default_rng(seed)
    boxes = [Box(f"b{k}", rng.uniform(0.2, 0.6, 3), rng.uniform(0, 1.5, 3)) for k in range(3)]
    points = rng.uniform(-0.2, 2.0, size=(500, 3))
    rows = contact_features(boxes, points, [(0, 1), (2, 0)])
    for row, (first, second) in zip(rows, [(0, 1), (2, 0)], strict=True):
        low = np.minimum(boxes[first].position - boxes[first].size / 2, boxes[second].position - boxes[second].size / 2)
        high = np.maximum(
            boxes[first].position + boxes[first].size / 2, boxes[second].position + boxes[second].size / 2
        )
        inside = sum(all(low[a] <= p[a] <= high[a] for a in range(3)) for p in points)
        assert named(row)["cloud_in_pair_box"] == pytest.approx(inside / len(points))
        assert 0.0 <= named(row)["cloud_between"] <= 1.0


def test_extended_set_appends_the_contact_features(stack: list[Box], rng: np.random.Generator) -> None:
    points = rng.uniform(0, 2, size=(200, 3))
    paper = pair_features(stack, points, [(0, 1), (2, 1)])
    extended = pair_features(stack, points, [(0, 1), (2, 1)], FeatureSettings(feature_set="extended"))
    assert extended.shape == (2, 36) and len(feature_names(FeatureSettings(feature_set="extended"))) == 36
    assert np.array_equal(extended[:, :19], paper)
    assert np.array_equal(extended[:, 19:], contact_features(stack, points, [(0, 1), (2, 1)]))


def test_unknown_feature_set_is_refused() -> None:
    with pytest.raises(UnstackError, match="unknown feature set 'deep'; expected one of paper, extended"):
        FeatureSettings(feature_set="deep")
