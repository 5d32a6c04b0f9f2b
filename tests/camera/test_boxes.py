"""One box per mask (unstack.camera.boxes): sizes told apart whatever the order they are given in."""

from __future__ import annotations

import numpy as np
import pytest

from unstack.camera.boxes import fit_box
from unstack.geometry import rotation_matrix

CAMERA = np.array([-2.5, 0.0, 1.6])


def _one_face_of_a_leaning_box(
    depth: float, lean_deg: float, rng: np.random.Generator
) -> tuple[np.ndarray, np.ndarray]:
    """Points of the 0.3 x 0.3 face of a box ``depth`` deep leaning back ``lean_deg`` (the face
    turned up towards the camera), its lowest edge on the floor; and the box's centre."""
    lean = np.radians(lean_deg)
    normal = np.array([-np.cos(lean), 0.0, np.sin(lean)])  # out of the face, towards the camera
    up_the_face = np.array([np.sin(lean), 0.0, np.cos(lean)])
    across = np.array([0.0, 1.0, 0.0])
    bottom_edge = np.array([2.0, 0.0, 0.0])  # the face's lowest edge, on the floor
    u, v = rng.uniform(0.0, 0.3, (2, 4000))
    face = bottom_edge + u[:, None] * up_the_face + (v[:, None] - 0.15) * across
    centre = bottom_edge + 0.15 * up_the_face - normal * depth / 2
    return face, centre


@pytest.mark.parametrize("lean_deg", [20.0, 35.0])
@pytest.mark.parametrize("sizes", [[(0.4, 0.3, 0.3), (0.3, 0.3, 0.2)], [(0.3, 0.3, 0.2), (0.4, 0.3, 0.3)]])
def test_a_tilted_box_showing_one_face_two_sizes_share_is_told_by_where_it_lands(
    lean_deg: float, sizes: list[tuple[float, ...]]
) -> None:
    # both sizes have the seen 0.3 x 0.3 face; the 0.4 deep one would reach under the floor
    face, centre = _one_face_of_a_leaning_box(0.2, lean_deg, np.random.default_rng(0))
    fitted = fit_box("a", face, known_sizes=sizes, surfaces=[0.0], rng=np.random.default_rng(1), viewpoint=CAMERA)
    assert fitted.face == "tilted"
    assert sorted(fitted.box.size) == pytest.approx([0.2, 0.3, 0.3])
    assert fitted.box.position == pytest.approx(centre, abs=0.01)
    assert fitted.partial  # the depth behind the face is not seen
    assert np.abs(rotation_matrix(fitted.box.orientation_xyzw)[2]).max() < np.cos(np.radians(5.0))


@pytest.mark.parametrize("sizes", [[(0.43, 0.3, 0.3), (0.42, 0.3, 0.3)], [(0.42, 0.3, 0.3), (0.43, 0.3, 0.3)]])
def test_an_upright_box_takes_the_nearer_of_two_sizes_of_one_height_in_either_order(
    sizes: list[tuple[float, ...]],
) -> None:
    # a 0.4 x 0.3 top at 0.3 m sampled every centimetre (measured 0.41 x 0.31): both sizes land on the
    # floor and are within SIZE_TIE of the top's edges, 0.42 nearer
    x, y = np.meshgrid(np.arange(0.8, 1.2001, 0.01), np.arange(-0.15, 0.1501, 0.01))
    top = np.column_stack([x.ravel(), y.ravel(), np.full(x.size, 0.3)])
    fitted = fit_box("a", top, known_sizes=sizes, surfaces=[0.0], rng=np.random.default_rng(1))
    assert fitted.face == "top"
    assert sorted(fitted.box.size) == pytest.approx([0.3, 0.3, 0.42])


def test_a_size_that_would_sink_the_box_into_the_floor_is_passed_over() -> None:
    # a 0.6 x 0.4 top 0.4 m up measured 3 cm long on each edge (flying pixels, noise): the edges
    # are nearer 0.6 x 0.5 of the 0.8 x 0.6 x 0.5 carton, which stood 0.8 m tall would sink 0.4 m
    x, y = np.meshgrid(np.arange(0.7, 1.3201, 0.01), np.arange(-0.2, 0.2201, 0.01))
    top = np.column_stack([x.ravel(), y.ravel(), np.full(x.size, 0.4)])
    sizes = [(0.8, 0.6, 0.5), (0.6, 0.4, 0.4)]
    fitted = fit_box("a", top, known_sizes=sizes, surfaces=[0.0], rng=np.random.default_rng(1))
    assert sorted(fitted.box.size) == pytest.approx([0.4, 0.4, 0.6])
    assert fitted.box.position[2] == pytest.approx(0.2)


@pytest.mark.parametrize("x", [-1.0, 0.0, 2.0])
@pytest.mark.parametrize("yaw_deg", [0.0, 50.0, -50.0])
def test_a_box_seen_from_the_front_only_lies_behind_its_front_as_the_camera_sees_it(x: float, yaw_deg: float) -> None:
    # the side of the face the box lay on was told by the face's place against the frame's origin,
    # not the camera: a front at x < 0, or turned from the door, had its box put in front of it
    along = np.radians(yaw_deg)
    outward = np.array([-np.cos(along), -np.sin(along), 0.0])  # the face looks this way, towards the camera
    across = np.array([-outward[1], outward[0], 0.0])
    u, z = np.meshgrid(np.arange(-0.2, 0.2001, 0.01), np.arange(0.0, 0.3001, 0.01))
    face_centre = np.array([x, 0.5, 0.0])
    front = face_centre + u.reshape(-1, 1) * across + z.reshape(-1, 1) * np.array([0.0, 0.0, 1.0])
    viewpoint = face_centre + 3.0 * outward + np.array([0.0, 0.0, 1.2])
    fitted = fit_box(
        "a", front, known_sizes=[(0.4, 0.3, 0.3)], surfaces=[0.0], rng=np.random.default_rng(1), viewpoint=viewpoint
    )
    assert fitted.face == "front"
    behind = (fitted.box.position - face_centre)[:2] @ outward[:2]
    assert behind == pytest.approx(-0.15, abs=0.01)


@pytest.mark.parametrize("face", [(0.4, 0.3), (0.3, 0.4), (0.3, 0.5), (0.5, 0.3)])
@pytest.mark.parametrize("sizes", [[(0.5, 0.4, 0.3)], [(0.3, 0.4, 0.5), (0.2, 0.2, 0.2)]])
def test_a_box_seen_from_the_front_only_stands_the_way_up_its_front_shows(
    face: tuple[float, float], sizes: list[tuple[float, ...]]
) -> None:
    # a front 0.3 wide and 0.4 tall was matched to a size's 0.4 x 0.3 face (sorted edges compared):
    # fitted lying, 0.1 m lower than it stands
    width, height = face
    y, z = np.meshgrid(np.arange(-width / 2, width / 2 + 1e-4, 0.01), np.arange(1.2, 1.2 + height + 1e-4, 0.01))
    front = np.column_stack([np.full(y.size, 2.0), y.ravel(), z.ravel()])
    fitted = fit_box("a", front, known_sizes=sizes, surfaces=[0.0, 1.2], rng=np.random.default_rng(1))
    assert fitted.face == "front"
    assert fitted.box.size[1:] == pytest.approx([width, height])
    assert fitted.box.position[2] == pytest.approx(1.2 + height / 2, abs=0.01)


@pytest.mark.parametrize("sizes", [[(0.4, 0.3, 0.3), (0.3, 0.3, 0.2)], [(0.3, 0.3, 0.2), (0.4, 0.3, 0.3)]])
def test_a_box_seen_from_the_front_only_takes_the_deeper_of_two_sizes_sharing_its_face(
    sizes: list[tuple[float, ...]],
) -> None:
    # a 0.3 x 0.3 front (x = 2.0, looking out through the door) with nothing of the top seen: the depth
    # behind it is 0.4 or 0.2 by the sizes, whatever order they come in; the fit says it saw it in part
    y, z = np.meshgrid(np.arange(-0.15, 0.1501, 0.01), np.arange(0.3, 0.6001, 0.01))
    front = np.column_stack([np.full(y.size, 2.0), y.ravel(), z.ravel()])
    fitted = fit_box("a", front, known_sizes=sizes, surfaces=[0.0, 0.3], rng=np.random.default_rng(1))
    assert fitted.face == "front"
    assert sorted(fitted.box.size) == pytest.approx([0.3, 0.3, 0.4])
    assert fitted.box.position[0] == pytest.approx(2.2, abs=0.01)  # the box lies behind its front
    assert fitted.partial


def _top_grid() -> np.ndarray:
    """A 0.5 x 0.4 m top at 0.4 m, one point a centimetre, 3.5-4 m from :data:`CAMERA`."""
    x, y = np.meshgrid(np.arange(1.0, 1.5001, 0.01), np.arange(-0.2, 0.2001, 0.01))
    return np.column_stack([x.ravel(), y.ravel(), np.full(x.size, 0.4)])


@pytest.mark.parametrize("seed", range(4))
def test_a_top_blurred_along_the_rays_is_measured_to_its_edges(seed: int) -> None:
    """Noise of 1.4 cm along the rays (a Kinect at 3 m) spreads the top 5-6 cm past its edges."""
    from unstack.camera.boxes import _spacing, _unblurred, min_area_rectangle

    top = _top_grid()
    rays = (top - CAMERA) / np.linalg.norm(top - CAMERA, axis=1, keepdims=True)
    blurred = (top + rays * np.random.default_rng(seed).normal(0.0, 0.014, (len(top), 1)))[:, :2]
    centre, yaw, extents = min_area_rectangle(blurred)
    extents = extents + _spacing(blurred)
    assert extents[0] > 0.55  # the extreme points: 5 cm long and more
    centre, unblurred = _unblurred(blurred, centre, yaw, extents)
    assert unblurred == pytest.approx([0.51, 0.41], abs=0.012)
    assert centre == pytest.approx([1.25, 0.0], abs=0.01)


def test_a_sharp_top_keeps_its_rectangle() -> None:
    from unstack.camera.boxes import _spacing, _unblurred, min_area_rectangle

    flat = _top_grid()[:, :2]
    centre, yaw, extents = min_area_rectangle(flat)
    extents = extents + _spacing(flat)
    kept_centre, kept = _unblurred(flat, centre, yaw, extents)
    assert np.array_equal(kept, extents) and np.array_equal(kept_centre, centre)
