"""The preorder table path for small groups against the brute-force oracle and the compiled walk."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from tests.conftest import random_probabilities
from tests.reasoner.oracle import brute_force
from unstack.errors import InvalidArgument, NoConsistentWorld
from unstack.reasoner.consistency import PREORDER_COUNTS, is_transitive
from unstack.reasoner.small import SMALL_MAX_BOXES, preorders, small_marginals


@pytest.mark.parametrize("n", range(SMALL_MAX_BOXES + 1))
def test_the_table_holds_every_preorder_once(n: int) -> None:
    table = preorders(n)
    assert len(table) == PREORDER_COUNTS[n]
    assert len({world.tobytes() for world in table}) == len(table)
    assert all(is_transitive(world) for world in table)
    assert not table[:, np.arange(n), np.arange(n)].any()


def test_the_table_size_is_checked() -> None:
    with pytest.raises(InvalidArgument, match="the preorder table holds 0 to 5 boxes, got 6"):
        preorders(6)


@pytest.mark.filterwarnings("ignore:invalid value encountered")
@settings(deadline=None, max_examples=40)
@given(
    st.integers(2, 4).flatmap(
        lambda n: arrays(np.float64, (n, n), elements=st.sampled_from([0.0, 1.0, 1e-9, 0.2, 0.5, 0.9, 1 - 1e-9]))
    )
)
def test_marginals_match_the_oracle(matrix: np.ndarray) -> None:
    np.fill_diagonal(matrix, 0.0)
    expected, worlds = brute_force(matrix)
    if worlds == 0:
        with pytest.raises(NoConsistentWorld):
            small_marginals(matrix)
        return
    marginals, counted, _ = small_marginals(matrix)
    np.testing.assert_allclose(marginals, expected, atol=1e-12)
    assert counted == worlds


@pytest.mark.parametrize("hard", [0.0, 0.3])
def test_five_boxes_match_the_compiled_walk(rng: np.random.Generator, hard: float) -> None:
    """A sixth box with no possible relation sends the same group through the compiled walk."""
    from unstack.reasoner.marginals import exact_marginals

    for _ in range(5):
        p = random_probabilities(5, rng, hard=hard)
        try:
            marginals, worlds, log_partition = small_marginals(p)
        except NoConsistentWorld:
            continue
        padded = np.zeros((6, 6))
        padded[:5, :5] = p
        compiled = exact_marginals(padded)
        np.testing.assert_allclose(compiled.marginals[:5, :5], marginals, atol=1e-12)
        assert compiled.consistent_worlds == worlds
        assert compiled.log_partition == pytest.approx(log_partition, abs=1e-9)
