"""Work shared between the steps of a plan: reused groups, warm chains, progress."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from tests.conftest import weak_groups
from unstack.reasoner.consistency import is_transitive
from unstack.reasoner.decision import decide
from unstack.reasoner.plan import unloading_plan
from unstack.reasoner.reuse import WorkCache
from unstack.reasoner.sampling import restrict_worlds, sample_worlds
from unstack.supports import Supports


def weak_pile(rng: np.random.Generator, sizes: list[int], link: float) -> Supports:
    """Groups of mostly weak pairs (``U(0.01, 0.08)``), 40 % of them strong, linked by ``link``."""
    probabilities = weak_groups(rng, sizes, link, inside=(0.01, 0.08), strong=0.4)
    return Supports([f"b{i:02d}" for i in range(sum(sizes))], probabilities)


@settings(max_examples=8, deadline=None)
@given(st.integers(0, 2**32 - 1), st.lists(st.booleans(), min_size=6, max_size=6))
def test_a_restricted_world_is_a_world(seed: int, keep_mask: list[bool]) -> None:
    p = np.random.default_rng(seed).uniform(0.0, 1.0, (6, 6))
    np.fill_diagonal(p, 0.0)
    worlds = sample_worlds(p, 3, seed=seed)
    bits = np.left_shift(np.int64(1), np.arange(6, dtype=np.int64))
    masks = (worlds * bits[None, None, :]).sum(axis=2).astype(np.int64)
    keep = np.flatnonzero(keep_mask)
    restricted = restrict_worlds(masks, keep)
    m = len(keep)
    small_bits = np.left_shift(np.int64(1), np.arange(m, dtype=np.int64))
    for k in range(3):
        relation = (restricted[k][:, None] & small_bits[None, :]) != 0
        assert np.array_equal(relation, worlds[k][np.ix_(keep, keep)])
        assert is_transitive(relation)


def test_unchanged_groups_are_reused_and_changed_ones_start_warm(rng: np.random.Generator) -> None:
    p = np.zeros((13, 13))
    inner = weak_pile(rng, [10], 0.0).probabilities
    p[:10, :10] = inner
    p[10:, 10:] = [[0, 0.3, 0.1], [0.6, 0, 0.2], [0.1, 0.1, 0]]
    supports = Supports([f"b{i:02d}" for i in range(13)], p)
    work = WorkCache()
    decide(supports, samples=256, seed=0, cache=work)
    assert work.reused == 0 and work.warm_starts == 0
    again = decide(supports.subset(supports.objects[1:]), samples=256, seed=0, cache=work)
    assert work.reused == 1 and work.warm_starts == 1  # the 3-box group is reused, the other starts warm
    fresh = decide(supports.subset(supports.objects[1:]), samples=256, seed=0)
    assert np.array_equal(again.marginals[9:, 9:], fresh.marginals[9:, 9:])


def test_a_sampled_plan_is_reproducible_and_reports_progress(rng: np.random.Generator) -> None:
    supports = weak_pile(rng, [4, 4, 2], 1e-3)
    heard: list[tuple[int, int]] = []
    first = unloading_plan(supports, seed=4, progress=lambda done, total: heard.append((done, total)))
    second = unloading_plan(supports, seed=4)
    assert first.to_dict() == second.to_dict()
    assert heard == [(k, 10) for k in range(1, 11)]
    assert sorted(first.order) == sorted(supports.objects)
