"""Argument constraints declared once, beside the function they constrain.

In the manner of scikit-learn's ``validate_params``: a public function is decorated with
the constraints of its arguments; every call checks them (one line,
:class:`~unstack.errors.InvalidArgument`, naming the argument and what it got), and the
command line reads the same constraints to type its options (:mod:`unstack.cli.options`),
so an option the library would refuse is refused by click with the library's words before
any work starts.

Examples
--------
>>> @validate_params({"piles": Interval(int, 1), "share": Interval(float, 0.0, 0.9)})
... def run(data: str, *, piles: int = 2, share: float = 0.0) -> int:
...     return piles
>>> run("d", piles=3)
3
>>> run("d", piles=0)
Traceback (most recent call last):
...
unstack.errors.InvalidArgument: piles must be at least 1, got 0
>>> constraints_of(run)["share"].check(0.95, "share")
Traceback (most recent call last):
...
unstack.errors.InvalidArgument: share must be at most 0.9, got 0.95
"""

from __future__ import annotations

import functools
import inspect
import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any, ParamSpec, TypeVar

import numpy as np

from unstack.errors import InvalidArgument

__all__ = [
    "COUNT",
    "DETECTOR_NOISE",
    "FOLDS",
    "ISET_SIZE",
    "JOBS",
    "LEARNING_SEED",
    "MAX_CONFIGS",
    "MAX_FOLDS",
    "MAX_JOBS",
    "MISSED_SHARE",
    "OPTIONAL_COUNT",
    "SEED",
    "Interval",
    "OneOf",
    "constraints_of",
    "validate_params",
]

_P = ParamSpec("_P")
_R = TypeVar("_R")
_ATTRIBUTE = "__unstack_constraints__"


@dataclass(frozen=True)
class Interval:
    """An integer or a finite number between ``low`` and ``high`` (both included; None: open).

    ``optional``: None is accepted too (an argument whose default is "not given").

    Examples
    --------
    >>> Interval(int, 2).check(np.int64(5), "r")
    5
    >>> Interval(float, 0.0, 0.1).check(0.05, "detector_noise")
    0.05
    >>> Interval(int, 1, optional=True).check(None, "max_picks") is None
    True
    """

    kind: type
    low: float | None = None
    high: float | None = None
    optional: bool = False

    def __post_init__(self) -> None:
        if self.kind not in (int, float):
            raise TypeError(f"Interval of int or float, not {self.kind!r}")

    def check(self, value: Any, name: str) -> Any:
        """The canonical value (``int`` or ``float``), or :class:`~unstack.errors.InvalidArgument`."""
        if value is None and self.optional:
            return None
        if isinstance(value, bool):
            raise InvalidArgument(f"{name} must be {self._what()}, got {value!r}")
        if self.kind is int:
            if not isinstance(value, int | np.integer):
                raise InvalidArgument(f"{name} must be an integer, got {value!r}")
            number: float = int(value)
        else:
            if not isinstance(value, int | float | np.integer | np.floating):
                raise InvalidArgument(f"{name} must be a number, got {value!r}")
            number = float(value)
            if not math.isfinite(number):
                raise InvalidArgument(f"{name} must be a finite number, got {number}")
        if self.low is not None and number < self.low:
            raise InvalidArgument(f"{name} must be at least {_shown(self.low)}, got {_shown(number)}")
        if self.high is not None and number > self.high:
            raise InvalidArgument(f"{name} must be at most {_shown(self.high)}, got {_shown(number)}")
        return number

    def _what(self) -> str:
        return "an integer" if self.kind is int else "a number"


def _shown(number: float) -> str:
    """``12``, ``0.9``, ``100,000,000``, ``1e+300``: a bound or a value as a message shows it.

    Examples
    --------
    >>> _shown(100_000_000), _shown(0.9), _shown(1e300)
    ('100,000,000', '0.9', '1e+300')
    """
    if float(number).is_integer() and 10_000 <= abs(number) < 1e15:
        return f"{int(number):,}"
    return str(int(number)) if isinstance(number, int) else f"{number:g}"


@dataclass(frozen=True)
class OneOf:
    """One of ``choices`` (strings).

    Examples
    --------
    >>> OneOf(("door", "any")).check("any", "reach")
    'any'
    """

    choices: tuple[str, ...]
    kind: type = str

    def check(self, value: Any, name: str) -> str:
        """The value, or :class:`~unstack.errors.InvalidArgument` naming the choices."""
        if not isinstance(value, str) or value not in self.choices:
            raise InvalidArgument(f"unknown {name} {value!r}; expected one of {', '.join(self.choices)}")
        return value


Constraint = Interval | OneOf


def validate_params(constraints: Mapping[str, Constraint]) -> Callable[[Callable[_P, _R]], Callable[_P, _R]]:
    """Decorate a function so that every call checks the named arguments first.

    Parameters
    ----------
    constraints : mapping of str to Interval or OneOf
        Per argument name (each must be a parameter of the function).

    Returns
    -------
    callable
        The decorator. The checked function keeps its signature and docstring; its
        constraints are :func:`constraints_of` it.
    """

    def decorate(function: Callable[_P, _R]) -> Callable[_P, _R]:
        signature = inspect.signature(function)
        unknown = sorted(set(constraints) - set(signature.parameters))
        if unknown:
            raise TypeError(f"{function.__qualname__} has no parameters {unknown}")

        @functools.wraps(function)
        def checked(*args: _P.args, **kwargs: _P.kwargs) -> _R:
            bound = signature.bind(*args, **kwargs)
            for name, constraint in constraints.items():
                if name in bound.arguments:
                    bound.arguments[name] = constraint.check(bound.arguments[name], name)
            return function(*bound.args, **bound.kwargs)

        setattr(checked, _ATTRIBUTE, dict(constraints))
        return checked

    return decorate


def constraints_of(function: Callable[..., Any]) -> dict[str, Constraint]:
    """The constraints :func:`validate_params` declared on ``function`` (empty if none).

    Examples
    --------
    >>> constraints_of(print)
    {}
    """
    return dict(getattr(function, _ATTRIBUTE, {}))


#: A count of at least one (piles, ISets, parallel processes).
COUNT = Interval(int, 1)
#: A count of at least one, or None ("every one", "no limit").
OPTIONAL_COUNT = Interval(int, 1, optional=True)
#: A seed: a non-negative integer.
SEED = Interval(int, 0)
#: A seed scikit-learn takes as ``random_state``: 0 to 2**32 - 1 (numpy's legacy seeding).
LEARNING_SEED = Interval(int, 0, 2**32 - 1)
#: The most worker processes a call starts (beyond, a typing slip: each is a whole Python).
MAX_JOBS = 256
#: Worker processes: at least one, at most :data:`MAX_JOBS`.
JOBS = Interval(int, 1, MAX_JOBS)
#: The most configurations a simulated data set holds (the paper's largest has 200; beyond, a typing slip).
MAX_CONFIGS = 100_000
#: Boxes per ISet (the paper's r): at least two.
ISET_SIZE = Interval(int, 2)
#: Cross-validation folds: at least two, at most a thousand (more is a typing slip; the folds a
#: fit uses are at most the rarer class's relations anyway).
MAX_FOLDS = 1000
FOLDS = Interval(int, 2, MAX_FOLDS)
#: Share of the seen boxes a simulated detector misses at each scan.
MISSED_SHARE = Interval(float, 0.0, 0.9)
#: Position error of a simulated box detector (metres).
DETECTOR_NOISE = Interval(float, 0.0, 0.1)
#: A share between none and all (a probability), or None for a default.
OPTIONAL_SHARE = Interval(float, 0.0, 1.0, optional=True)
