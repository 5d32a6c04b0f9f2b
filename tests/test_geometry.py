"""Box geometry: footprints, overlaps and distances against brute-force answers."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from unstack.geometry import (
    box_corners,
    convex_hull_2d,
    convex_overlap,
    footprint,
    footprint_overlap_area,
    points_in_box,
    polygon_area,
    polygon_distance,
    tilt_deg,
)
from unstack.scene import Box


def _yawed(size: list[float], position: list[float], yaw_deg: float) -> Box:
    half = np.radians(yaw_deg) / 2
    return Box("b", size, position, [0.0, 0.0, np.sin(half), np.cos(half)])


@settings(max_examples=40, deadline=None)
@given(
    st.floats(-45, 45), st.floats(-45, 45), st.floats(-0.5, 0.5), st.floats(-0.5, 0.5),
)  # fmt: skip
def test_footprint_overlap_matches_a_monte_carlo_estimate(yaw_a: float, yaw_b: float, dx: float, dy: float) -> None:
    first = _yawed([0.6, 0.4, 0.3], [0.0, 0.0, 0.15], yaw_a)
    second = _yawed([0.5, 0.3, 0.3], [dx, dy, 0.45], yaw_b)
    rng = np.random.default_rng(0)
    samples = rng.uniform(-1.0, 1.0, size=(40_000, 3)) * [1, 1, 0] + [0, 0, 0.15]
    inside_first = points_in_box(samples, first)
    lifted = samples + np.array([0.0, 0.0, 0.3])
    inside_both = inside_first & points_in_box(lifted, second)
    estimate = inside_both.mean() * 4.0
    exact = footprint_overlap_area(footprint(first), footprint(second))
    assert exact == pytest.approx(estimate, abs=0.01)
    assert exact <= min(polygon_area(footprint(first)), polygon_area(footprint(second))) + 1e-12


@settings(max_examples=40, deadline=None)
@given(st.floats(-45, 45), st.floats(-45, 45), st.floats(-0.6, 0.6), st.floats(-0.6, 0.6))
def test_the_overlap_polygon_lies_in_both_and_has_the_overlap_area(
    yaw_a: float, yaw_b: float, dx: float, dy: float
) -> None:
    first = footprint(_yawed([0.6, 0.4, 0.3], [0.0, 0.0, 0.15], yaw_a))
    second = footprint(_yawed([0.5, 0.3, 0.3], [dx, dy, 0.45], yaw_b))
    overlap = convex_overlap(first, second)
    assert polygon_area(overlap) == pytest.approx(footprint_overlap_area(second, first), abs=1e-12)
    for polygon in (first, second):  # every corner of the overlap is in (or on) both polygons
        edges = np.roll(polygon, -1, axis=0) - polygon
        for corner in overlap:
            offsets = corner - polygon
            assert np.all(edges[:, 0] * offsets[:, 1] - edges[:, 1] * offsets[:, 0] >= -1e-9)


def test_polygons_that_do_not_meet_overlap_in_no_corner() -> None:
    square = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], dtype=float)
    assert convex_overlap(square, square + 2.0).shape == (0, 2)


def test_polygon_distance_of_separated_squares_is_the_gap() -> None:
    square = convex_hull_2d(np.array([[0, 0], [1, 0], [1, 1], [0, 1]], dtype=float))
    assert polygon_distance(square, square + np.array([1.5, 0.0])) == pytest.approx(0.5)
    assert polygon_distance(square, square + np.array([0.5, 0.5])) == 0.0


def test_a_box_turned_about_z_is_upright_and_a_tipped_one_is_not() -> None:
    assert tilt_deg(_yawed([0.4, 0.3, 0.2], [0, 0, 0.1], 40.0)) == pytest.approx(0.0, abs=1e-9)
    half = np.radians(20) / 2
    tipped = Box("t", [0.4, 0.3, 0.2], [0, 0, 0.3], [0.0, np.sin(half), 0.0, np.cos(half)])
    assert tilt_deg(tipped) == pytest.approx(20.0)


def test_corners_span_the_box_size_along_its_axes() -> None:
    corners = box_corners(Box("a", [0.6, 0.4, 0.2], [1.0, 2.0, 0.1]))
    assert np.ptp(corners, axis=0) == pytest.approx([0.6, 0.4, 0.2])
