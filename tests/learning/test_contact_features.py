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


def reference_cloud(bb_x: np.ndarray, bb_y: np.ndarray, points: np.ndarray) -> list[float]:
    """The cloud columns written out with numpy masks, one pair at a time (the oracle)."""

    def column(low: np.ndarray, high: np.ndarray) -> np.ndarray:
        return (
            (points[:, 0] >= low[0]) & (points[:, 0] <= high[0]) & (points[:, 1] >= low[1]) & (points[:, 1] <= high[1])
        )

    def above(bb: np.ndarray) -> tuple[float, float]:
        over = column(bb[:2], bb[3:5]) & (points[:, 2] > bb[5] + 0.01)
        return (float(points[over, 2].max() - bb[5]), float(over.mean())) if over.any() else (0.0, 0.0)

    low, high = np.maximum(bb_x[:2], bb_y[:2]) - 0.05, np.minimum(bb_x[3:5], bb_y[3:5]) + 0.05
    bottom, top = bb_x[5] + 0.01, bb_y[2] - 0.01
    between = 0.0
    if not (np.any(high <= low) or top <= bottom):
        between = float((column(low, high) & (points[:, 2] > bottom) & (points[:, 2] < top)).mean())
    pair_low, pair_high = np.minimum(bb_x[:3], bb_y[:3]), np.maximum(bb_x[3:], bb_y[3:])
    in_pair_box = float(np.all((points >= pair_low) & (points <= pair_high), axis=1).mean())
    (rise_x, share_x), (rise_y, share_y) = above(bb_x), above(bb_y)
    return [between, rise_x, rise_y, share_x, share_y, in_pair_box]


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_cloud_columns_match_numpy_masks(seed: int) -> None:
    from unstack.geometry import bounding_boxes

    rng = np.random.default_rng(seed)
    turns = rng.normal(size=(4, 4))
    turns /= np.linalg.norm(turns, axis=1, keepdims=True)
    centres = rng.uniform([0.5, 0.5, 0.0], [1.0, 1.0, 1.5], size=(4, 3))  # close: footprints overlap
    boxes = [Box(f"b{k}", rng.uniform(0.2, 0.6, 3), centres[k], turns[k]) for k in range(4)]
    points = rng.uniform(-0.2, 2.0, size=(500, 3))
    points[:20] = np.round(points[:20], 1)  # some points on faces and edges
    pairs = [(0, 1), (1, 0), (2, 3), (3, 1)]
    rows = contact_features(boxes, points, pairs)
    bounds = bounding_boxes(boxes)
    for row, (first, second) in zip(rows, pairs, strict=True):
        assert row[10:16] == pytest.approx(reference_cloud(bounds[first], bounds[second], points), abs=1e-12)
        assert 0.0 <= named(row)["cloud_between"] <= 1.0


@pytest.mark.parametrize("cell", [0.01, 0.3, 5.0])
def test_counts_do_not_depend_on_the_grid(
    cell: float, monkeypatch: pytest.MonkeyPatch, rng: np.random.Generator
) -> None:
    import unstack.learning.contact_features as module

    boxes = [Box(f"b{k}", [0.4, 0.3, 0.3], [0.2 * k, 0.1 * k, 0.15 + 0.3 * k]) for k in range(5)]
    points = rng.uniform(-0.5, 2.0, size=(3000, 3))
    pairs = [(i, j) for i in range(5) for j in range(5) if i != j]
    expected = contact_features(boxes, points, pairs)
    monkeypatch.setattr(module, "GRID_CELL", cell)
    assert np.array_equal(contact_features(boxes, points, pairs), expected)
    assert expected[:, 15].min() > 0  # every pair box holds points: the counts are not trivially 0


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
