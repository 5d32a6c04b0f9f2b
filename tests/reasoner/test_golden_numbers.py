"""The reasoner's numbers on fixed inputs are those recorded before the sampler's refactoring."""

from __future__ import annotations

import json

import pytest

from tests.reasoner.golden_numbers import GOLDEN_FILE, differences, golden_numbers

pytestmark = pytest.mark.slow  # samples 12-70 boxes, plans 31 and loads the default model


def test_decisions_plans_and_sampled_marginals_match_the_recorded_numbers() -> None:
    changed = differences(json.loads(GOLDEN_FILE.read_text()), golden_numbers(), tolerance=1e-12)
    assert not changed, "\n".join(changed[:20])


@pytest.mark.parametrize(
    ("recorded", "present", "expected"),
    [
        (
            {"order": ["a", "b"]},
            {"order": ["b", "a"]},
            ["order[0]: recorded 'a', now 'b'", "order[1]: recorded 'b', now 'a'"],
        ),
        ({"x": [1.0]}, {"x": [1.0 + 1e-9]}, ["x[0]: recorded 1.0, now 1.000000001"]),
        ({"sha256": "a", "x": 1.0}, {"sha256": "b", "x": 1.0}, []),
        ({"x": 1}, {"y": 1}, [".: keys ['x'] recorded, ['y'] now"]),
    ],
)
def test_the_comparison_reports_each_difference_by_its_path(
    recorded: dict[str, object], present: dict[str, object], expected: list[str]
) -> None:
    assert differences(recorded, present, tolerance=1e-12) == expected


def test_the_exact_comparison_holds_digests_and_floats_to_the_last_bit() -> None:
    assert differences({"sha256": "a", "x": 1.0}, {"sha256": "b", "x": 1.0 + 1e-15}) == [
        "sha256: recorded 'a', now 'b'",
        "x: recorded 1.0, now 1.000000000000001",
    ]
