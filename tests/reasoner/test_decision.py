"""Decisions (Eqs. 11-13): properties that hold for any input, ties, costs, methods."""

from __future__ import annotations

import itertools
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from unstack.errors import InvalidArgument, NoConsistentWorld, TooLarge, UnstackError
from unstack.reasoner import decide
from unstack.reasoner.plan import unloading_plan
from unstack.supports import Supports

probability_values = st.one_of(
    st.floats(0.0, 1.0, allow_nan=False),
    st.sampled_from([0.0, 1.0, 0.5, 0.01, 0.99]),
)


@st.composite
def support_matrices(draw: st.DrawFn, max_n: int = 5) -> np.ndarray:
    n = draw(st.integers(1, max_n))
    values = draw(arrays(np.float64, (n, n), elements=st.floats(0.0, 1.0, allow_nan=False)))
    np.fill_diagonal(values, 0.0)
    return values


def ids(n: int) -> list[str]:
    return [f"box{i}" for i in range(n)]


FAST = settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])


@FAST
@given(support_matrices())
def test_marginals_are_probabilities_and_costs_are_row_sums(probabilities: np.ndarray) -> None:
    try:
        decision = decide(Supports(ids(len(probabilities)), probabilities), method="exact")
    except NoConsistentWorld:
        return
    assert np.all((decision.marginals >= 0) & (decision.marginals <= 1))
    assert np.all(np.diag(decision.marginals) == 0)
    np.testing.assert_allclose(decision.expected_costs, decision.marginals.sum(axis=1), atol=1e-12)
    assert decision.choice in decision.ties
    assert decision.expected_costs[decision.objects.index(decision.choice)] == pytest.approx(
        decision.expected_costs.min(), abs=1e-12
    )


@FAST
@given(support_matrices(), st.randoms(use_true_random=False))
def test_permuting_the_boxes_permutes_every_output(probabilities: np.ndarray, random: object) -> None:
    n = len(probabilities)
    order = list(range(n))
    random.shuffle(order)  # type: ignore[attr-defined]
    names = ids(n)
    try:
        original = decide(Supports(names, probabilities), method="exact")
    except NoConsistentWorld:
        return
    permuted = decide(Supports([names[i] for i in order], probabilities[np.ix_(order, order)]), method="exact")
    np.testing.assert_allclose(permuted.marginals, original.marginals[np.ix_(order, order)], atol=1e-12)
    np.testing.assert_allclose(permuted.expected_costs, original.expected_costs[order], atol=1e-12)
    assert permuted.choice == original.choice
    assert permuted.consistent_worlds == original.consistent_worlds


@settings(max_examples=30, deadline=None)
@given(st.integers(2, 7), st.integers(0, 2**32 - 1))
def test_certain_chain_yields_its_transitive_closure(n: int, seed: int) -> None:
    order = np.random.default_rng(seed).permutation(n)
    closure = np.zeros((n, n))
    for i, below in enumerate(order):
        closure[below, order[i + 1 :]] = 1.0
    # Certain links of the chain; the implied relations are uncertain (0.5), the rest 0.
    probabilities = 0.5 * closure
    for below, above in itertools.pairwise(order):
        probabilities[below, above] = 1.0
    decision = decide(Supports(ids(n), probabilities), method="exact")
    np.testing.assert_array_equal(decision.marginals, closure)
    assert decision.consistent_worlds == 1
    assert decision.choice == f"box{order[-1]}"


@pytest.mark.parametrize("n", [1, 2, 3, 4, 5])
def test_methods_agree(n: int, rng: np.random.Generator) -> None:
    methods_agree(n, rng)


@pytest.mark.slow
def test_methods_agree_at_six_boxes(rng: np.random.Generator) -> None:
    methods_agree(6, rng)


def methods_agree(n: int, rng: np.random.Generator) -> None:
    probabilities = rng.uniform(0.05, 0.95, (n, n))
    np.fill_diagonal(probabilities, 0.0)
    supports = Supports(ids(n), probabilities)
    exact, sat = decide(supports, method="exact"), decide(supports, method="sat")
    np.testing.assert_allclose(exact.marginals, sat.marginals, atol=1e-12)
    assert exact.choice == sat.choice
    assert exact.consistent_worlds == sat.consistent_worlds


def test_one_box_costs_nothing() -> None:
    decision = decide(Supports(["only"], [[0.0]]))
    assert decision.choice == "only"
    assert decision.expected_costs.tolist() == [0.0]
    assert decision.consistent_worlds == 1


def test_ties_go_to_the_smallest_id() -> None:
    decision = decide(Supports(["zeta", "alpha", "mid"], np.zeros((3, 3))))
    assert decision.ties == ("alpha", "mid", "zeta")
    assert decision.choice == "alpha"


def test_mass_cost_weights_supported_boxes() -> None:
    # x supports y (light), z supports w (heavy): both have EC 0.9 boxes, masses decide.
    probabilities = np.zeros((4, 4))
    probabilities[0, 1] = 0.9
    probabilities[2, 3] = 0.9
    supports = Supports(["x", "y", "z", "w"], probabilities, masses=[1.0, 2.0, 1.0, 30.0])
    decision = decide(supports, cost="mass")
    np.testing.assert_allclose(decision.expected_costs, [1.8, 0.0, 27.0, 0.0])
    assert decision.choice == "w"


def test_mass_cost_without_masses_says_what_is_missing() -> None:
    with pytest.raises(UnstackError, match=r"\$\.masses: the mass-weighted cost needs box masses"):
        decide(Supports(["a", "b"], [[0, 0.5], [0.5, 0]]), cost="mass")


def test_auto_samples_groups_beyond_exact_reach(rng: np.random.Generator) -> None:
    dense = rng.uniform(0.1, 0.9, (9, 9))
    np.fill_diagonal(dense, 0.0)
    decision = decide(Supports(ids(9), dense), samples=800, seed=0)
    assert decision.method == "approx" and decision.component_methods == ("approx",)
    assert decision.expected_cost_errors is not None and np.all(decision.expected_cost_errors > 0)
    assert 0.0 < decision.choice_probability <= 1.0
    assert decide(Supports(ids(9), np.zeros((9, 9)))).consistent_worlds == 1  # nine unlinked boxes


def test_auto_samples_groups_of_more_than_63_boxes(rng: np.random.Generator) -> None:
    """No cap at 63 boxes: a 70-box group is sampled (word-array kernels), its errors reported."""
    sparse = rng.uniform(0.001, 0.02, (70, 70))
    sparse[:5, :5] = rng.uniform(0.1, 0.9, (5, 5))
    np.fill_diagonal(sparse, 0.0)
    decision = decide(Supports(ids(70), sparse), samples=64, seed=0)
    assert decision.component_methods == ("approx",) and len(decision.expected_costs) == 70
    assert decision.expected_cost_errors is not None and np.all(decision.expected_cost_errors > 0)
    assert np.all((decision.marginals >= 0.0) & (decision.marginals <= 1.0))


def test_explicit_exact_method_keeps_its_limit(rng: np.random.Generator) -> None:
    dense = rng.uniform(0.1, 0.9, (9, 9))
    np.fill_diagonal(dense, 0.0)
    with pytest.raises(TooLarge, match="9 boxes: the exact engine is limited to 8 boxes"):
        decide(Supports(ids(9), dense), method="exact")


def test_unknown_method_is_rejected() -> None:
    with pytest.raises(UnstackError, match="unknown method 'fast'"):
        decide(Supports(["a"], [[0.0]]), method="fast")


def test_ranking_puts_the_choice_first_then_ties_then_by_cost() -> None:
    from unstack.reasoner.decision import decide as decide_supports

    p = np.zeros((4, 4))
    p[3, 0] = 0.5  # d may support a: EC(d) = 0.5, the others 0 (tied; smallest id "a" wins)
    decision = decide_supports(Supports(["c", "a", "b", "d"], p), cost="count")
    assert [box for box, _, _ in decision.ranking()] == ["a", "b", "c", "d"]
    assert decision.ranking()[0][0] == decision.choice
    assert [error for _, _, error in decision.ranking()] == [0.0] * 4


def test_the_json_is_canonical_and_timing_only_on_request() -> None:
    import json

    import jsonschema

    from unstack.jsonio import load_schema
    from unstack.reasoner.decision import decide as decide_supports

    rng = np.random.default_rng(3)
    p = rng.uniform(0.05, 0.95, (10, 10))
    np.fill_diagonal(p, 0.0)
    supports = Supports([f"b{i}" for i in range(10)], p)
    first = decide_supports(supports, method="approx", samples=512, seed=7).to_dict()
    second = decide_supports(supports, method="approx", samples=512, seed=7).to_dict()
    assert json.dumps(first) == json.dumps(second)
    assert "timing" not in first and "seconds" not in first and "seconds" not in first["sampling"]
    timed = decide_supports(supports, samples=512, seed=7).to_dict(timing=True)
    assert set(timed["timing"]) == {"seconds", "sampling_seconds"}
    for document in (first, timed):
        jsonschema.validate(document, load_schema("unstack.decision/1"))


def test_warnings_come_from_the_supports_metadata() -> None:
    from unstack.reasoner.decision import decide as decide_supports

    supports = Supports(["a", "b"], [[0, 0.2], [0.7, 0]], metadata={"warnings": ["box a floats 0.3 m above b"]})
    decision = decide_supports(supports)
    assert decision.warnings == ("box a floats 0.3 m above b",)
    assert decision.to_dict()["warnings"] == ["box a floats 0.3 m above b"]


def test_a_contradiction_names_the_file(tmp_path: Path) -> None:
    from unstack.errors import NoConsistentWorld
    from unstack.reasoner.decision import decide as decide_supports
    from unstack.supports import load_supports

    file = tmp_path / "contradiction.json"
    Supports(["a", "b", "c"], [[0, 1, 0], [0, 0, 1], [0, 0, 0]]).save(file)
    with pytest.raises(
        NoConsistentWorld,
        match=r"contradiction\.json: \$\.probabilities\[0\]\[2\]: no consistent world: P\(SUPP\(a, b\)\) = 1",
    ):
        decide_supports(load_supports(file))


def test_default_budget_is_a_number_of_sweeps_reproducible_for_a_seed() -> None:
    from unstack.reasoner.decision import decide as decide_supports
    from unstack.reasoner.sampling import default_samples

    rng = np.random.default_rng(5)
    p = rng.uniform(0.05, 0.95, (9, 9))
    np.fill_diagonal(p, 0.0)
    supports = Supports([f"b{i}" for i in range(9)], p)
    first, second = (decide_supports(supports, seed=11) for _ in range(2))
    assert first.sampling is not None and first.sampling["samples"] == [default_samples(9)] == [8192]
    np.testing.assert_array_equal(first.expected_costs, second.expected_costs)
    np.testing.assert_array_equal(first.expected_cost_errors, second.expected_cost_errors)


@pytest.mark.parametrize("method", ["exact", "sat"])
def test_a_sample_budget_for_a_method_that_counts_every_world_is_refused(method: str) -> None:
    supports = Supports(["a", "b"], [[0, 0.2], [0.7, 0]])
    with pytest.raises(InvalidArgument, match=f"samples: method '{method}' samples nothing"):
        decide(supports, method=method, samples=100)
    assert unloading_plan(supports, method=method).order == ["a", "b"]


@pytest.mark.parametrize("method", ["exact", "sat"])
def test_a_time_limit_for_a_method_that_cannot_stop_early_is_refused(method: str) -> None:
    with pytest.raises(InvalidArgument, match=f"time_limit: method '{method}' counts every world and cannot stop"):
        decide(Supports(["a", "b"], [[0, 0.2], [0.7, 0]]), method=method, time_limit=0.001)


def test_a_progress_that_cannot_be_called_is_refused_before_any_step() -> None:
    with pytest.raises(InvalidArgument, match="progress must be a callable progress\\(done, total\\), got int"):
        unloading_plan(Supports(["a", "b"], [[0, 0.2], [0.7, 0]]), progress=42)  # type: ignore[arg-type]


@pytest.mark.parametrize(
    ("seconds", "methods", "said"),
    [
        (1.1, ["approx"], None),  # within 1.5 times the limit and a second
        (5.6, ["approx"], "the least sampling of a group of 3 linked boxes"),
        (5.6, ["exact"], "reading the evidence and counting took longer"),
    ],
)
def test_a_decision_far_past_its_time_limit_says_why(seconds: float, methods: list[str], said: str | None) -> None:
    from unstack.reasoner.decision import _overrun

    warning = _overrun(0.1, seconds, [[0, 1, 2]], methods)
    assert (warning == ()) if said is None else (said in warning[0] and f"took {seconds:.1f} s" in warning[0])
    assert _overrun(None, 100.0, [[0, 1, 2]], methods) == ()
