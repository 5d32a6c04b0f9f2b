"""Argument constraints declared once (unstack.parameters) and the CLI options typed from them."""

from __future__ import annotations

import inspect
from typing import Any

import click
import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from unstack.cli.experiments import experiment
from unstack.cli.options import constrained
from unstack.errors import InvalidArgument
from unstack.experiments.belief_calibration import belief_calibration
from unstack.experiments.container import container_experiment
from unstack.experiments.decisions import evaluate_decisions
from unstack.experiments.fig5a import fig5a
from unstack.parameters import COUNT, MISSED_SHARE, SEED, Interval, OneOf, validate_params


@pytest.mark.parametrize(
    ("constraint", "value", "message"),
    [
        (COUNT, 0, "piles must be at least 1, got 0"),
        (COUNT, 2.0, "piles must be an integer, got 2.0"),
        (COUNT, True, "piles must be an integer, got True"),
        (SEED, -1, "piles must be at least 0, got -1"),
        (MISSED_SHARE, 0.95, "piles must be at most 0.9, got 0.95"),
        (MISSED_SHARE, float("nan"), "piles must be a finite number, got nan"),
        (MISSED_SHARE, "half", "piles must be a number, got 'half'"),
        (Interval(int, 1, 100_000_000), 200_000_000, "piles must be at most 100,000,000, got 200,000,000"),
        (OneOf(("door", "any")), "window", "unknown piles 'window'; expected one of door, any"),
    ],
)
def test_a_value_outside_its_constraint_is_refused_naming_the_argument(
    constraint: Any, value: Any, message: str
) -> None:
    with pytest.raises(InvalidArgument, match=f"^{message.replace('(', '[(]').replace(')', '[)]')}$"):
        constraint.check(value, "piles")


@given(st.integers(min_value=1, max_value=10**12))
def test_an_integer_within_its_interval_comes_back_as_a_python_int(value: int) -> None:
    checked = COUNT.check(np.int64(value), "piles")
    assert checked == value and type(checked) is int


@given(st.floats(min_value=0.0, max_value=0.9))
def test_a_share_within_its_interval_comes_back_as_a_python_float(value: float) -> None:
    checked = MISSED_SHARE.check(np.float32(value), "share")
    assert type(checked) is float and 0.0 <= checked <= 0.9


def test_a_decorated_function_checks_positional_and_keyword_arguments_before_running() -> None:
    calls = []

    @validate_params({"piles": COUNT, "seed": SEED})
    def run(data: str, piles: int = 2, *, seed: int = 0) -> tuple[int, int]:
        calls.append(data)
        return piles, seed

    assert run("d", np.int64(3), seed=np.int64(4)) == (3, 4)  # type: ignore[arg-type]
    with pytest.raises(InvalidArgument, match=r"^piles must be at least 1, got 0$"):
        run("d", 0)
    with pytest.raises(InvalidArgument, match=r"^seed must be at least 0, got -2$"):
        run("d", seed=-2)
    assert calls == ["d"]
    assert inspect.signature(run).parameters["piles"].default == 2  # the signature is kept


def test_a_constraint_on_a_parameter_the_function_lacks_is_a_programming_error() -> None:
    with pytest.raises(TypeError, match=r"has no parameters \['pile'\]"):

        @validate_params({"pile": COUNT})
        def run(piles: int) -> int:
            return piles


@pytest.mark.parametrize(
    ("function", "arguments", "message"),
    [
        (container_experiment, {"piles": 0}, "piles must be at least 1, got 0"),
        (container_experiment, {"detector_misses": 1.0}, "detector_misses must be at most 0.9, got 1"),
        (container_experiment, {"reach": "window"}, "unknown reach 'window'; expected one of door, any"),
        (container_experiment, {"occupancy": 1.5}, "occupancy must be at most 1, got 1.5"),
        (belief_calibration, {"worlds": 0}, "worlds must be at least 1, got 0"),
        (evaluate_decisions, {"r": 1}, "r must be at least 2, got 1"),
        (evaluate_decisions, {"draw": "all"}, "unknown draw 'all'; expected one of random, neighbours, mixed"),
        (fig5a, {"cv": 1}, "cv must be at least 2, got 1"),
        (fig5a, {"split_by": "boxes"}, "unknown split_by 'boxes'; expected one of pairs, configuration"),
    ],
)
def test_an_experiment_refuses_a_bad_argument_before_reading_any_data(
    function: Any, arguments: dict[str, Any], message: str
) -> None:
    model = () if function is fig5a or function is belief_calibration else (None,)
    with pytest.raises(InvalidArgument, match=f"^{message}$"):
        function("no-such-folder", *model, **arguments)


def test_every_experiment_option_with_a_range_takes_it_from_a_library_constraint() -> None:
    loose = [
        f"{name} {parameter.opts[0]}"
        for name, command in experiment.commands.items()
        for parameter in command.params
        if isinstance(parameter, click.Option) and isinstance(parameter.type, click.IntRange | click.FloatRange)
    ]
    assert loose == ["generalisation --seeds", "generalisation --first-seed"]  # the suite's own, not a library's


def test_a_cli_option_refuses_what_the_library_refuses_in_the_same_words() -> None:
    option_type = constrained(container_experiment, "detector_misses")
    with pytest.raises(click.BadParameter) as refused:
        option_type.convert("0.95", None, None)
    with pytest.raises(InvalidArgument) as library:
        container_experiment("no-such-folder", None, detector_misses=0.95)
    assert refused.value.message == str(library.value)


def test_an_option_for_a_parameter_without_a_constraint_is_a_programming_error() -> None:
    with pytest.raises(TypeError, match="declares no constraint on 'model'"):
        constrained(container_experiment, "model")


def test_a_long_choice_is_one_word_in_the_help_and_its_names_are_in_the_error() -> None:
    from unstack.cli.options import CHOICES_LISTED
    from unstack.experiments.pick_responses import BEHAVIOURS, collect_pick_responses

    assert len(BEHAVIOURS) > CHOICES_LISTED
    option_type = constrained(collect_pick_responses, "behaviour")
    assert option_type.name == "behaviour" and option_type.convert("highest", None, None) == "highest"
    with pytest.raises(click.BadParameter, match="unknown behaviour 'tallest'; expected one of mixed, unstack, "):
        option_type.convert("tallest", None, None)
    assert isinstance(constrained(container_experiment, "reach"), click.Choice)  # a short one lists its names
