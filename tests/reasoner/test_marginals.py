"""The exact engine agrees with SAT enumeration and with brute force to 1e-12."""

from __future__ import annotations

import numpy as np
import pytest

from tests.conftest import random_probabilities, supports_of
from tests.reasoner.oracle import brute_force
from unstack.errors import NumericalRangeError, TooLarge
from unstack.reasoner import enumerate_worlds, exact_marginals, propagate_evidence


@pytest.mark.parametrize("n", [1, 2, 3, 4])
@pytest.mark.parametrize("hard", [0.0, 0.3])
def test_exact_matches_brute_force(n: int, hard: float, rng: np.random.Generator) -> None:
    probabilities = random_probabilities(n, rng, hard=hard)
    expected, count = brute_force(probabilities)
    result = exact_marginals(probabilities)
    np.testing.assert_allclose(result.marginals, expected, atol=1e-12, rtol=0)
    assert result.consistent_worlds == count


@pytest.mark.parametrize("n", [2, 3, 4, 5])
@pytest.mark.parametrize("hard", [0.0, 0.25])
def test_exact_matches_sat(n: int, hard: float, rng: np.random.Generator) -> None:
    exact_matches_sat(n, hard, rng)


@pytest.mark.slow
@pytest.mark.parametrize("hard", [0.0, 0.25])
def test_exact_matches_sat_at_six_boxes(hard: float, rng: np.random.Generator) -> None:
    exact_matches_sat(6, hard, rng)


def exact_matches_sat(n: int, hard: float, rng: np.random.Generator) -> None:
    probabilities = random_probabilities(n, rng, hard=hard)
    if hard:
        probabilities[0, 1] = 1.0  # hard evidence of both kinds
        probabilities = propagate_evidence([f"b{i}" for i in range(n)], probabilities).probabilities
    worlds = enumerate_worlds(supports_of(probabilities))
    result = exact_marginals(probabilities)
    np.testing.assert_allclose(result.marginals, worlds.marginals(), atol=1e-12, rtol=0)
    assert result.consistent_worlds == len(worlds)


def test_the_parallel_split_at_seven_boxes_agrees_with_serial_sat_enumeration(rng: np.random.Generator) -> None:
    """n = 7 cuts the tree into parallel tasks below level 2; SAT lists the same worlds one by one."""
    probabilities = random_probabilities(7, rng, hard=0.6)  # hard zeros keep the worlds to thousands
    result = exact_marginals(probabilities)
    worlds = enumerate_worlds(supports_of(probabilities), max_boxes=7)
    np.testing.assert_allclose(result.marginals, worlds.marginals(), atol=1e-12, rtol=0)
    assert result.consistent_worlds == len(worlds)


def test_one_thread_gives_the_same_bits_as_all_threads(rng: np.random.Generator) -> None:
    """The subtrees run on the engine's own threads and are summed in task order."""
    from concurrent.futures import ThreadPoolExecutor

    import numba

    probabilities = random_probabilities(7, rng)

    def on_one_thread() -> np.ndarray:
        numba.set_num_threads(1)  # local to this worker thread
        return exact_marginals(probabilities).marginals

    with ThreadPoolExecutor(max_workers=1) as pool:
        serial = pool.submit(on_one_thread).result()
    assert np.array_equal(exact_marginals(probabilities).marginals, serial)


def test_extreme_probabilities_do_not_overflow() -> None:
    probabilities = np.full((5, 5), 1 - 1e-15)
    np.fill_diagonal(probabilities, 0.0)
    result = exact_marginals(probabilities)
    assert np.all(np.isfinite(result.marginals))
    np.testing.assert_allclose(result.marginals[~np.eye(5, dtype=bool)], 1.0, atol=1e-9)


def test_worlds_breaking_near_certain_relations_stay_representable() -> None:
    # Every consistent world must break one of the near-certain relations 0->1->2 (odds
    # 1e-16) or add 0->2 (p = 1e-200): weights far below 1, marginals still exact.
    probabilities = np.full((3, 3), 1e-200)
    probabilities[0, 1] = probabilities[1, 2] = 1 - 1e-16
    np.fill_diagonal(probabilities, 0.0)
    result = exact_marginals(probabilities)
    np.testing.assert_allclose(result.marginals, brute_force(probabilities)[0], atol=1e-12)
    assert result.log_partition < -30


def test_partition_below_the_guard_is_a_clear_error(monkeypatch: pytest.MonkeyPatch) -> None:
    import unstack.reasoner.marginals as marginals_module

    probabilities = np.full((6, 6), 1e-200)  # 6 boxes: the compiled walk (float64 weights)
    probabilities[0, 1] = probabilities[1, 2] = 1 - 1e-16
    np.fill_diagonal(probabilities, 0.0)
    monkeypatch.setattr(marginals_module, "SMALLEST_PARTITION", 1e-10)  # the real guard is 1e-280
    with pytest.raises(NumericalRangeError, match=r"too extreme for float64.*method 'sat'"):
        exact_marginals(probabilities)


def test_small_groups_work_in_log_space_below_the_guard(monkeypatch: pytest.MonkeyPatch) -> None:
    import unstack.reasoner.marginals as marginals_module

    probabilities = np.full((3, 3), 1e-200)
    probabilities[0, 1] = probabilities[1, 2] = 1 - 1e-16
    np.fill_diagonal(probabilities, 0.0)
    monkeypatch.setattr(marginals_module, "SMALLEST_PARTITION", 1e-10)
    result = exact_marginals(probabilities)
    np.testing.assert_allclose(result.marginals, brute_force(probabilities)[0], atol=1e-12)


def test_size_limit_is_a_clear_error() -> None:
    with pytest.raises(TooLarge, match=r"9 boxes: the exact engine is limited to 8 boxes \(n = 9 has 6.3e\+10"):
        exact_marginals(np.zeros((9, 9)))


def test_sat_size_limit_is_a_clear_error() -> None:
    with pytest.raises(TooLarge, match=r"limited to 6 boxes .* decide without listing them \(unstack decide FILE"):
        enumerate_worlds(supports_of(np.zeros((7, 7))))
