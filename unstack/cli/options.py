"""Click parameter types whose constraints are the library's own argument checks.

A command-line option and the library argument it feeds are checked by one function
(:mod:`unstack.reasoner.arguments`, or the constraints a function declares with
:func:`unstack.parameters.validate_params`): the bounds are declared once, and an option
that the library would refuse is refused by click with the library's words, before any work.

Examples
--------
>>> import click
>>> from unstack.reasoner.arguments import check_samples
>>> samples = Checked(int, check_samples)
>>> samples.convert("64", None, None)
64
>>> try:
...     samples.convert("0", None, None)
... except click.BadParameter as error:
...     print(error.message)
samples must be at least 1, got 0

An option typed from a library function's declared constraints:

>>> from unstack.experiments.container import container_experiment
>>> constrained(container_experiment, "detector_misses").convert("0.5", None, None)
0.5
>>> list(constrained(container_experiment, "reach").choices)
['door', 'any']
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import click

from unstack.errors import InvalidArgument
from unstack.parameters import OneOf, constraints_of

__all__ = ["Checked", "constrained", "scheduler_option", "setting"]


if TYPE_CHECKING:
    _ParamType = click.ParamType[Any]  # generic in the click that type-checks us
else:
    _ParamType = click.ParamType  # not subscriptable before click 8.2


#: A choice among more than this many names shows as one word in ``--help`` (the names are in
#: the error a wrong one gets), not as a list that buries the other options.
CHOICES_LISTED = 12
_READERS: dict[type, Any] = {int: click.INT, float: click.FLOAT, str: click.STRING}


class Checked(_ParamType):
    """An option of type ``kind`` (int, float or str) that must pass ``check(value)``.

    Parameters
    ----------
    kind : type
        ``int``, ``float`` or ``str``: what the text is read as.
    check : callable
        The library's check: returns the canonical value or raises
        :class:`~unstack.errors.InvalidArgument`.
    name : str, optional
        What ``--help`` calls the value (default: integer, number or text).
    """

    def __init__(self, kind: type, check: Callable[[Any], Any], name: str | None = None) -> None:
        self.kind = kind
        self.check = check
        self.name = name or {int: "integer", float: "number"}.get(kind, "text")

    def convert(self, value: Any, param: click.Parameter | None, ctx: click.Context | None) -> Any:
        read = _READERS[self.kind].convert(value, param, ctx)
        try:
            return self.check(read)
        except InvalidArgument as error:
            self.fail(str(error), param, ctx)


def constrained(function: Callable[..., Any], parameter: str) -> _ParamType:
    """The click type of an option feeding ``parameter`` of ``function``: its declared constraint.

    A choice becomes :class:`click.Choice` (the choices show in ``--help``), or, beyond
    :data:`CHOICES_LISTED` choices, a :class:`Checked` name; a range, a :class:`Checked`
    number running the constraint's check.

    Parameters
    ----------
    function : callable
        A function decorated with :func:`unstack.parameters.validate_params`.
    parameter : str
        The name of the argument the option feeds.
    """
    constraints = constraints_of(function)
    if parameter not in constraints:
        raise TypeError(f"{function.__qualname__} declares no constraint on {parameter!r}")
    constraint = constraints[parameter]
    if isinstance(constraint, OneOf) and len(constraint.choices) > CHOICES_LISTED:
        return Checked(str, functools.partial(constraint.check, name=parameter), name=parameter)
    if isinstance(constraint, OneOf):
        return click.Choice(list(constraint.choices))
    return Checked(constraint.kind, functools.partial(constraint.check, name=parameter))


def setting(field: str, kind: type) -> Checked:
    """The click type of an option that sets one simulation setting (``Class.field``): the check a
    settings file's field gets (:func:`unstack.sim.settings.check_setting`).

    Examples
    --------
    >>> setting("GroundTruthSettings.horizon", float).convert("2", None, None)
    2.0
    """
    from unstack.sim.settings import check_setting

    return Checked(kind, functools.partial(check_setting, field=field))


def _scheduler_address(address: str) -> str:
    from unstack.sim.dataset import check_scheduler_address  # only when an address is given

    try:
        return check_scheduler_address(address)
    except InvalidArgument as error:  # click names the option already
        raise InvalidArgument(str(error).removeprefix("scheduler: ")) from None


def scheduler_option(tasks: str) -> Callable[[Any], Any]:
    """The ``--scheduler`` option of a command whose ``tasks`` (piles, configurations) may run on a
    dask.distributed cluster: the address checked when read, one of it or ``--jobs``."""
    return click.option(
        "--scheduler",
        type=Checked(str, _scheduler_address, name="address"),
        default=None,
        help=f"Address of a dask.distributed scheduler (tcp://HOST:PORT): {tasks} run on its workers "
        "(instead of --jobs).",
    )
