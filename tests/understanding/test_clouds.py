"""Surface-sampled clouds: what the viewpoint sees, at the spacing asked."""

from __future__ import annotations

import numpy as np
import pytest

from unstack.errors import UnstackError
from unstack.geometry import points_in_box
from unstack.scene import Box
from unstack.understanding.clouds import surface_cloud, vary_cloud


def test_only_faces_towards_the_viewpoint_are_sampled() -> None:
    box = Box("a", [0.4, 0.4, 0.4], [1.0, 0.0, 0.2])
    cloud = surface_cloud([box], viewpoint=[-2.0, 0.0, 0.2], floor=False, seed=0)
    assert len(cloud) > 0
    assert np.allclose(cloud[:, 0], 0.8)  # the front face only


def test_a_box_behind_another_is_hidden() -> None:
    front = Box("front", [0.3, 1.0, 1.0], [1.0, 0.0, 0.5])
    behind = Box("behind", [0.3, 0.4, 0.4], [1.6, 0.0, 0.2])
    cloud = surface_cloud([front, behind], viewpoint=[-2.0, 0.0, 0.5], floor=False, seed=0)
    assert not points_in_box(cloud, behind, margin=0.005).any()


def test_density_follows_the_spacing() -> None:
    box = Box("a", [0.4, 0.4, 0.4], [1.0, 0.0, 0.2])
    coarse = surface_cloud([box], spacing=0.04, floor=False, seed=0)
    fine = surface_cloud([box], spacing=0.01, floor=False, seed=0)
    assert len(fine) / len(coarse) == pytest.approx(16, rel=0.3)


def test_bad_settings_are_refused() -> None:
    with pytest.raises(UnstackError, match="spacing > 0"):
        surface_cloud([], spacing=0.0)


def test_a_varied_cloud_is_a_noisy_subset() -> None:
    rng = np.random.default_rng(0)
    cloud = rng.uniform(0, 1, size=(20_000, 3))
    varied = vary_cloud(cloud, np.random.default_rng(1), keep_range=(0.5, 0.5), max_depth_noise=0.0, max_holes=0)
    assert len(varied) == pytest.approx(10_000, rel=0.05)
