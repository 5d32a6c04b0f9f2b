"""Checks of the arguments of the reasoner's public functions (one place, one style).

Each check returns the canonical value or raises :class:`~unstack.errors.InvalidArgument`
(an :class:`~unstack.errors.UnstackError` and a :class:`ValueError`) naming the argument
and what it got. Messages speak of arguments, never of command-line flags.

Examples
--------
>>> check_budget(2.5, "time_limit")
2.5
>>> check_budget(float("nan"), "time_limit")
Traceback (most recent call last):
...
unstack.errors.InvalidArgument: time_limit must be a positive, finite number of seconds, got nan
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from unstack.checks import number_text
from unstack.errors import InvalidArgument, InvalidFile
from unstack.parameters import Interval, OneOf

__all__ = [
    "MAX_SAMPLES",
    "MAX_SECONDS",
    "check_budget",
    "check_choice",
    "check_count",
    "check_flag",
    "check_margin",
    "check_matrix",
    "check_samples",
    "check_seed",
]

#: The largest number of recorded sweeps accepted: more is a typing error more often than a plan
#: (10**8 sweeps of 40 boxes take about a quarter of an hour on 2 cores).
MAX_SAMPLES = 100_000_000
#: The longest time limit accepted, in seconds (a day).
MAX_SECONDS = 86_400.0


def _real_number(value: Any, name: str, unit: str) -> float:
    """``value`` as a float when it is a real number (not a bool); else the error naming ``unit``."""
    if isinstance(value, bool) or not isinstance(value, int | float | np.integer | np.floating):
        raise InvalidArgument(f"{name} must be a number of {unit}, got {value!r}")
    try:
        return float(value)
    except OverflowError:  # an integer beyond the largest float
        from unstack.checks import number_text

        raise InvalidArgument(f"{name} must be a finite number of {unit}, got {number_text(value)}") from None


def check_budget(value: Any, name: str) -> float:
    """A positive, finite number of seconds (``time_limit``).

    Parameters
    ----------
    value : float
        The argument.
    name : str
        Its name, for the message.

    Returns
    -------
    float

    Examples
    --------
    >>> check_budget(1, "time_limit")
    1.0
    """
    seconds = _real_number(value, name, "seconds")
    if not (math.isfinite(seconds) and seconds > 0):
        raise InvalidArgument(f"{name} must be a positive, finite number of seconds, got {seconds}")
    if seconds > MAX_SECONDS:
        said = f"{seconds:,.0f}" if seconds < 1e15 else f"{seconds:.3g}"  # 1e300 is no 300-digit line
        raise InvalidArgument(f"{name} must be at most {MAX_SECONDS:,.0f} seconds (a day), got {said}")
    return seconds


def check_samples(value: Any) -> int:
    """A number of recorded sweeps: an integer from 1 to :data:`MAX_SAMPLES`.

    Examples
    --------
    >>> check_samples(4096)
    4096
    """
    samples = check_count(value, "samples")
    if samples > MAX_SAMPLES:
        said = f"{samples:,}" if samples < 10**15 else number_text(samples)  # 10**400 is no 400-digit line
        raise InvalidArgument(
            f"samples must be at most {MAX_SAMPLES:,} (about a quarter of an hour for 40 boxes on 2 cores), "
            f"got {said}; give a time limit for a longer run"
        )
    return samples


def check_margin(value: Any, name: str) -> float:
    """A non-negative, finite number of expected boxes moved (``near_tie_margin``).

    Examples
    --------
    >>> check_margin(0, "near_tie_margin")
    0.0
    """
    margin = _real_number(value, name, "expected boxes moved")
    if not (math.isfinite(margin) and margin >= 0):
        raise InvalidArgument(f"{name} must be a finite number >= 0 (expected boxes moved), got {margin}")
    return margin


def check_count(value: Any, name: str, minimum: int = 1) -> int:
    """An integer of at least ``minimum`` (``samples``, ``chains``, ``max_boxes``).

    Examples
    --------
    >>> check_count(np.int64(4), "samples")
    4
    """
    checked: int = Interval(int, minimum).check(value, name)
    return checked


def check_seed(value: Any) -> int | None:
    """``None`` or a non-negative integer.

    Examples
    --------
    >>> check_seed(None) is None
    True
    """
    if value is None:
        return None
    return check_count(value, "seed", minimum=0)


def check_choice(value: Any, name: str, choices: tuple[str, ...]) -> str:
    """One of ``choices``.

    Examples
    --------
    >>> check_choice("exact", "method", ("exact", "sat"))
    'exact'
    """
    return OneOf(choices).check(value, name)


def check_flag(value: Any, name: str) -> bool:
    """``True`` or ``False`` (numpy's booleans too, as numpy's numbers are numbers elsewhere).

    Examples
    --------
    >>> check_flag(np.True_, "statics")
    True
    """
    if not isinstance(value, bool | np.bool_):
        raise InvalidArgument(f"{name} must be True or False, got {value!r}")
    return bool(value)


def check_matrix(value: Any, name: str = "probabilities") -> np.ndarray:
    """A square matrix of support probabilities (finite, in [0, 1], zero diagonal), as float64.

    Examples
    --------
    >>> check_matrix([[0, 0.5], [0.2, 0]]).dtype
    dtype('float64')
    """
    from unstack.checks import check_probability_matrix

    shape = np.shape(value) if isinstance(value, np.ndarray | list | tuple) else None
    if shape is None or len(shape) != 2 or shape[0] != shape[1] or shape[0] < 1:
        got = f"shape {shape}" if shape is not None else type(value).__name__
        raise InvalidArgument(f"{name} must be a non-empty square matrix, got {got}")
    try:
        return check_probability_matrix(value, shape[0], source=name, path="$")
    except InvalidFile as error:
        raise InvalidArgument(f"{name}{error.json_path[1:]}: {error.message}") from None
