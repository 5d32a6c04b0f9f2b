"""Blocks of strongly linked boxes and the block Gibbs step of the sampler, against exact answers."""

from __future__ import annotations

import networkx as nx
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from tests.conftest import weak_groups
from tests.reasoner.oracle import assert_within_errors
from unstack.reasoner.block_gibbs import BLOCK_STRIDE, block_tables, strong_blocks
from unstack.reasoner.consistency import PREORDER_COUNTS
from unstack.reasoner.marginals import exact_marginals
from unstack.reasoner.sampling import sampled_marginals
from unstack.reasoner.small import small_marginals


@settings(max_examples=40, deadline=None)
@given(arrays(np.float64, (9, 9), elements=st.sampled_from([0.0, 1e-4, 0.01, 0.03, 0.5, 1.0])))
def test_blocks_are_the_small_strongly_linked_groups(p: np.ndarray) -> None:
    np.fill_diagonal(p, 0.0)
    blocks = strong_blocks(p, threshold=0.02)
    graph = nx.Graph()
    graph.add_nodes_from(range(9))
    graph.add_edges_from(zip(*np.nonzero(np.maximum(p, p.T) > 0.02), strict=True))
    expected = sorted(sorted(group) for group in nx.connected_components(graph) if 2 <= len(group) <= 5)
    assert sorted(block.tolist() for block in blocks) == expected


def test_tables_hold_every_preorder_and_the_blocks_own_marginals(rng: np.random.Generator) -> None:
    p = weak_groups(rng, [5, 3, 2], 1e-3)
    blocks = strong_blocks(p)
    assert [block.tolist() for block in blocks] == [[0, 1, 2, 3, 4], [5, 6, 7], [8, 9]]
    tables = block_tables(p, blocks)
    assert tables.counts.tolist() == [PREORDER_COUNTS[5], PREORDER_COUNTS[3], PREORDER_COUNTS[2]]
    for k, block in enumerate(blocks):
        size = len(block)
        expected = small_marginals(p[np.ix_(block, block)])[0]
        got = tables.marginals[k].reshape(BLOCK_STRIDE, BLOCK_STRIDE)[:size, :size]
        np.testing.assert_allclose(got, expected, atol=1e-12)
        assert len(set(tables.masks[k, : tables.counts[k]].tolist())) == tables.counts[k]
    assert tables.block_of.tolist() == [0] * 5 + [1] * 3 + [2] * 2


def test_a_block_with_certain_relations_gives_the_small_engines_marginals(rng: np.random.Generator) -> None:
    p = weak_groups(rng, [4, 3], 1e-3)
    p[0, 1], p[2, 1], p[4, 5] = 1.0, 0.0, 1.0
    tables = block_tables(p, strong_blocks(p))
    for k, block in enumerate(strong_blocks(p)):
        size = len(block)
        expected = small_marginals(p[np.ix_(block, block)])[0]
        got = tables.marginals[k].reshape(BLOCK_STRIDE, BLOCK_STRIDE)[:size, :size]
        np.testing.assert_allclose(got, expected, atol=1e-12)
        impossible = ~np.isfinite(tables.log_weights[k, : tables.counts[k]])
        assert 0 < impossible.sum() < tables.counts[k]  # the preorders that break a certain relation
    assert tables.counts[1] < tables.counts[0] and np.all(tables.pairs[1, tables.counts[1] :] == 0.0)  # padding


@pytest.mark.parametrize("link", [1e-3, 0.02])
def test_block_gibbs_agrees_with_the_exact_engine(rng: np.random.Generator, link: float) -> None:
    """Weak links (blocks mostly alone) and links at the threshold (relations across constrain the blocks)."""
    p = weak_groups(rng, [4, 3], link)
    exact = exact_marginals(p).marginals
    assert_within_errors(sampled_marginals(p, samples=8_000, seed=3), exact)


@pytest.mark.slow
def test_hard_evidence_inside_a_block_is_respected(rng: np.random.Generator) -> None:
    p = weak_groups(rng, [4, 4], 0.01)
    p[0, 1] = 1.0
    p[1, 2] = 0.0
    p[0, 2] = 0.0  # with 0 -> 1 forced, 1 -> 2 is forbidden by transitivity too
    exact = exact_marginals(p).marginals
    result = sampled_marginals(p, samples=4_000, seed=0)
    assert result.marginals[0, 1] == 1.0 and result.marginals[1, 2] == 0.0 and result.marginals[0, 2] == 0.0
    assert np.abs(result.marginals - exact).max() < 0.05


def test_same_seed_same_numbers_with_blocks(rng: np.random.Generator) -> None:
    p = weak_groups(rng, [5, 5, 5], 1e-3)
    first = sampled_marginals(p, samples=256, seed=7)
    second = sampled_marginals(p, samples=256, seed=7)
    assert np.array_equal(first.marginals, second.marginals)
    assert np.array_equal(first.standard_errors, second.standard_errors)
