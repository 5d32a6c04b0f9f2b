"""The sampler kernels' word-array layout (groups of 64 boxes and more) against the one-word one."""

from __future__ import annotations

import numpy as np
import pytest

from tests.conftest import weak_groups
from unstack.reasoner.consistency import is_transitive
from unstack.reasoner.sampling import restrict_worlds, sample_worlds, sampled_marginals
from unstack.reasoner.world_masks import pack, unpack


@pytest.mark.parametrize("shape", [(1, 7), (3, 4), (4, 5)])
def test_both_layouts_give_the_same_numbers(rng: np.random.Generator, shape: tuple[int, int]) -> None:
    """Same seed, same moves, same random numbers: identical estimates and final states
    without blocks; with blocks (linked ones sum precomputed weights in the word-array
    layout) the same to rounding."""
    p = weak_groups(rng, [shape[1]] * shape[0], 1e-3)
    seed = int(rng.integers(2**31))
    one_word = sampled_marginals(p, samples=64, seed=seed, blocks=False)
    words = sampled_marginals(p, samples=64, seed=seed, blocks=False, wide=True)
    assert np.array_equal(one_word.marginals, words.marginals)
    assert np.array_equal(one_word.standard_errors, words.standard_errors)
    assert one_word.acceptance == words.acceptance
    assert words.final_worlds is not None and words.final_worlds.shape == (8, len(p), 1)
    assert np.array_equal(one_word.final_worlds, words.final_worlds[..., 0])
    with_blocks = sampled_marginals(p, samples=64, seed=seed)
    wide_blocks = sampled_marginals(p, samples=64, seed=seed, wide=True)
    np.testing.assert_allclose(wide_blocks.marginals, with_blocks.marginals, rtol=0.0, atol=1e-12)


def test_more_than_63_boxes_sample_transitive_worlds(rng: np.random.Generator) -> None:
    """A 70-box group (two words per set): every drawn world is transitive, relations reach
    across the word boundary, and a restriction to few boxes is a world in the one-word layout."""
    p = rng.uniform(0.0, 0.05, (70, 70))
    p[60:68, 60:68] = rng.uniform(0.3, 0.9, (8, 8))  # a dense group across bit 63 / 64
    np.fill_diagonal(p, 0.0)
    worlds = sample_worlds(p, 4, seed=int(rng.integers(2**31)), burn_in=4)
    assert all(is_transitive(world) for world in worlds)
    assert worlds[:, 60:64, 64:68].any() or worlds[:, 64:68, 60:64].any()
    masks = pack(worlds)
    assert masks.shape == (4, 70, 2)
    keep = np.array([1, 62, 63, 64, 65, 69])
    restricted = restrict_worlds(masks, keep)
    assert restricted.shape == (4, 6)
    assert np.array_equal(unpack(restricted, 6), worlds[:, keep][:, :, keep])


def test_more_than_63_boxes_agree_with_the_groups_alone(rng: np.random.Generator) -> None:
    """14 groups of 5 with links of 1e-6: the marginals inside each group are the group's
    exact ones to within the links' effect, and every relation across stays near 1e-6."""
    from unstack.reasoner.marginals import exact_marginals

    p = weak_groups(rng, [5] * 14, 1e-6)
    result = sampled_marginals(p, samples=64, seed=int(rng.integers(2**31)))
    for g in range(14):
        block = slice(5 * g, 5 * g + 5)
        exact = exact_marginals(p[block, block]).marginals
        assert np.abs(result.marginals[block, block] - exact).max() < 1e-3
    across = np.kron(1 - np.eye(14), np.ones((5, 5))).astype(bool)
    assert result.marginals[across].max() < 1e-3


def test_rare_sweeps_across_weak_links_widen_the_errors(rng: np.random.Generator) -> None:
    """Two groups of 3 joined by 1e-4: the blocks' exact marginals hide the rare sweeps with a
    relation across, so the batch means alone gave standard errors far below the true error
    (53 % coverage on two groups of 4); with the rare-event floor every EC lies within 3
    standard errors."""
    from unstack.reasoner.marginals import exact_marginals

    p = weak_groups(rng, [3] * 2, 1e-4)
    result = sampled_marginals(p, samples=4096, seed=int(rng.integers(2**31)))
    costs, covariance = result.errors_of(np.ones(6))
    errors = np.sqrt(np.diag(covariance))
    floor = result.rare_event_floor(np.ones(6))
    assert result.link_rates is not None and np.all(result.link_rates * result.samples < 30)
    assert np.all(floor > 0) and np.all(errors >= floor)
    assert np.all(np.abs(costs - exact_marginals(p).marginals.sum(axis=1)) <= 3 * errors)


def test_a_plan_step_starts_warm_across_the_63_box_boundary(rng: np.random.Generator) -> None:
    """Chains of a 66-box group (word arrays) warm-start the 65- and 63-box groups left after
    picks (word arrays, then one word): the restricted worlds are consistent starts."""
    from unstack.reasoner.decision import decide
    from unstack.reasoner.reuse import WorkCache
    from unstack.supports import Supports

    p = rng.uniform(0.001, 0.01, (66, 66))
    p[60:66, 60:66] = rng.uniform(0.2, 0.9, (6, 6))
    np.fill_diagonal(p, 0.0)
    supports = Supports([f"b{i:02d}" for i in range(66)], p)
    work = WorkCache()
    decide(supports, samples=32, seed=0, cache=work)
    for left in (65, 63):
        step = decide(supports.subset(supports.objects[66 - left :]), samples=32, seed=0, cache=work)
        assert np.all(np.isfinite(step.expected_costs)) and len(step.expected_costs) == left
    assert work.warm_starts == 2
    assert work.chains[tuple(supports.objects[3:])].shape == (8, 63)
