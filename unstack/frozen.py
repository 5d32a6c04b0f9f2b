"""Setting the checked fields of a frozen dataclass from its own ``__init__``.

The data model's classes (:class:`~unstack.scene.Box`, :class:`~unstack.scene.Scene`,
:class:`~unstack.supports.Supports`, :class:`~unstack.pictures.values.DecisionValues`) check
and convert their inputs in ``__init__`` and are frozen afterwards; a frozen dataclass refuses
``self.name = value``, so the canonical values are set past its ``__setattr__``.
"""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["read_only", "set_frozen_fields"]


def read_only(array: np.ndarray, given: Any = None) -> np.ndarray:
    """``array`` made read-only, copied first where it holds the caller's ``given`` data: the
    data model freezes its own arrays, never the caller's.

    Examples
    --------
    >>> mine = np.zeros(3)
    >>> frozen = read_only(mine, mine)
    >>> frozen.flags.writeable, mine.flags.writeable, frozen is mine
    (False, True, False)
    """
    if isinstance(given, np.ndarray) and np.may_share_memory(array, given):
        array = array.copy()
    array.setflags(write=False)
    return array


def set_frozen_fields(instance: Any, **fields: Any) -> None:
    """Set ``fields`` on a frozen dataclass ``instance`` (from its ``__init__`` only).

    Examples
    --------
    >>> from dataclasses import dataclass
    >>> @dataclass(frozen=True, init=False)
    ... class Span:
    ...     low: float
    ...     high: float
    ...     def __init__(self, low: float, high: float) -> None:
    ...         set_frozen_fields(self, low=min(low, high), high=max(low, high))
    >>> Span(2.0, 1.0)
    Span(low=1.0, high=2.0)
    """
    for name, value in fields.items():
        object.__setattr__(instance, name, value)
