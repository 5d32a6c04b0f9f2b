"""The last two levels summed by transforms agree with independent counts to 1e-12.

The compiled walk sums the last two boxes at each node of level ``n - 2`` with subset-sum
transforms (``collapse=2``, the default). It is checked against the brute-force oracle
(n <= 4), the preorder table of the small engine (n <= 5), every preorder on six boxes
weighted in numpy (n = 6), and the direct pair sum of the last level (``collapse=1``,
n = 6..8), on dense matrices and on matrices with hard 0/1 evidence.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from tests.conftest import random_probabilities
from tests.reasoner.oracle import brute_force
from unstack.errors import NoConsistentWorld, NumericalRangeError
from unstack.reasoner.consistency import PREORDER_COUNTS
from unstack.reasoner.marginals import _compiled_marginals
from unstack.reasoner.small import _extend, preorders, small_marginals

RTOL = 1e-12
ATOL = 1e-15


def with_evidence(n: int, rng: np.random.Generator, share: float) -> np.ndarray:
    """Dense probabilities with a share of pairs set to exactly 0 and a few to exactly 1."""
    probabilities = random_probabilities(n, rng)
    hard = rng.random((n, n)) < share
    probabilities[hard] = 0.0
    probabilities[0, 1] = 1.0  # one certain relation: its worlds are forced, not excluded
    probabilities[1, 0] = 0.0
    np.fill_diagonal(probabilities, 0.0)
    return probabilities


def table_marginals(probabilities: np.ndarray, worlds: np.ndarray) -> tuple[np.ndarray, int]:
    """Marginals and count of non-zero-weight worlds from a table of preorders ``(w, n, n)``."""
    n = probabilities.shape[0]
    off = ~np.eye(n, dtype=bool)
    bits = worlds[:, off]
    p = probabilities[off]
    weights = np.prod(np.where(bits, p, 1.0 - p), axis=1)
    marginals = np.zeros((n, n))
    marginals[off] = weights @ bits / weights.sum()
    return marginals, int(np.count_nonzero(weights))


def assert_agree(result_marginals: np.ndarray, expected: np.ndarray) -> None:
    np.testing.assert_allclose(result_marginals, expected, rtol=RTOL, atol=ATOL)


@pytest.mark.parametrize("collapse", [1, 2])
@pytest.mark.parametrize("n", [2, 3, 4])
@pytest.mark.parametrize("share", [0.0, 0.3])
def test_compiled_walk_matches_brute_force(collapse: int, n: int, share: float, rng: np.random.Generator) -> None:
    probabilities = with_evidence(n, rng, share) if share else random_probabilities(n, rng)
    expected, count = brute_force(probabilities)
    result = _compiled_marginals(probabilities, collapse)
    assert_agree(result.marginals, expected)
    assert result.consistent_worlds == count


@pytest.mark.parametrize("n", [3, 4, 5])
@pytest.mark.parametrize("share", [0.0, 0.2])
def test_compiled_walk_matches_the_preorder_table(n: int, share: float, rng: np.random.Generator) -> None:
    probabilities = with_evidence(n, rng, share) if share else random_probabilities(n, rng)
    expected, count, log_partition = small_marginals(probabilities)
    result = _compiled_marginals(probabilities)
    assert_agree(result.marginals, expected)
    assert result.consistent_worlds == count
    assert result.log_partition == pytest.approx(log_partition, rel=RTOL, abs=1e-13)


@pytest.fixture(scope="module")
def six_box_preorders() -> np.ndarray:
    """All 209,527 preorders on six boxes, built from the five-box table."""
    return _extend(preorders(5))


@pytest.mark.parametrize("share", [0.0, 0.2])
def test_six_boxes_match_every_preorder_weighted_in_numpy(
    six_box_preorders: np.ndarray, share: float, rng: np.random.Generator
) -> None:
    assert len(six_box_preorders) == PREORDER_COUNTS[6]
    probabilities = with_evidence(6, rng, share) if share else random_probabilities(6, rng)
    expected, count = table_marginals(probabilities, six_box_preorders)
    result = _compiled_marginals(probabilities)
    assert_agree(result.marginals, expected)
    assert result.consistent_worlds == count


@pytest.mark.parametrize("n", [6, 7])
@pytest.mark.parametrize("share", [0.0, 0.15])
def test_transforms_match_the_direct_pair_sum(n: int, share: float, rng: np.random.Generator) -> None:
    probabilities = with_evidence(n, rng, share) if share else random_probabilities(n, rng)
    direct = _compiled_marginals(probabilities, collapse=1)
    transformed = _compiled_marginals(probabilities, collapse=2)
    assert_agree(transformed.marginals, direct.marginals)
    assert transformed.consistent_worlds == direct.consistent_worlds
    assert transformed.log_partition == pytest.approx(direct.log_partition, rel=RTOL, abs=1e-13)


@pytest.mark.slow
@pytest.mark.parametrize("share", [0.0, 0.1])
def test_transforms_match_the_direct_pair_sum_at_eight_boxes(share: float, rng: np.random.Generator) -> None:
    probabilities = with_evidence(8, rng, share) if share else random_probabilities(8, rng)
    direct = _compiled_marginals(probabilities, collapse=1)
    transformed = _compiled_marginals(probabilities, collapse=2)
    assert_agree(transformed.marginals, direct.marginals)
    assert transformed.consistent_worlds == direct.consistent_worlds
    if not share:
        assert transformed.consistent_worlds == PREORDER_COUNTS[8]


@settings(max_examples=60, deadline=None)
@given(
    st.integers(2, 5).flatmap(
        lambda n: arrays(np.float64, (n, n), elements=st.sampled_from([0.0, 1e-3, 0.2, 0.5, 0.9, 1.0]))
    )
)
def test_any_evidence_pattern_matches_the_preorder_table(probabilities: np.ndarray) -> None:
    np.fill_diagonal(probabilities, 0.0)
    try:
        expected, count, _ = small_marginals(probabilities)
    except NoConsistentWorld:
        with pytest.raises(NumericalRangeError):
            _compiled_marginals(probabilities)
        return
    result = _compiled_marginals(probabilities)
    assert_agree(result.marginals, expected)
    assert result.consistent_worlds == count
