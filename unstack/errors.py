"""Errors raised by unstack.

Every error a user can cause is an :class:`UnstackError`; the command line turns it into
one line on standard error and exit code 2. Errors about a file carry the file name and
the JSON path of the offending value, so the line reads
``scene.json: $.boxes[2].size[0]: expected a positive number, got -0.4``.

Examples
--------
>>> from unstack.errors import InvalidSupports
>>> str(InvalidSupports("piles.json", "$.probabilities[0][0]", "expected 0 on the diagonal, got 0.3"))
'piles.json: $.probabilities[0][0]: expected 0 on the diagonal, got 0.3'
"""

from __future__ import annotations

__all__ = [
    "InvalidArgument",
    "InvalidFile",
    "InvalidScene",
    "InvalidSupports",
    "ModelRequired",
    "NoConsistentWorld",
    "NumericalRangeError",
    "TooLarge",
    "UnknownFormat",
    "UnstackError",
]


class UnstackError(Exception):
    """Root of every error unstack raises for a user's mistake or an impossible request."""


class InvalidArgument(UnstackError, ValueError):
    """A function argument out of its domain (a negative time limit, an unknown method name).

    Also a :class:`ValueError`, so callers that catch the standard exception still catch it.

    Examples
    --------
    >>> isinstance(InvalidArgument("samples must be at least 1, got 0"), ValueError)
    True
    """


class InvalidFile(UnstackError):
    """A file (or in-memory value) that does not match what was expected.

    Parameters
    ----------
    source : str
        The file name, ``<stdin>``, or a name for an in-memory value such as ``<array>``.
    json_path : str
        Where in the document the problem is, as a JSONPath (``$`` is the document).
    message : str
        What was expected and what was found.
    """

    def __init__(self, source: str, json_path: str, message: str) -> None:
        self.source = source
        self.json_path = json_path
        self.message = message
        super().__init__(f"{source}: {json_path}: {message}")


class UnknownFormat(InvalidFile):
    """The ``format`` tag names a format or a version this release cannot read."""


class InvalidSupports(InvalidFile):
    """An ``unstack.supports/1`` document or support-probability matrix is not valid."""


class InvalidScene(InvalidFile):
    """An ``unstack.scene/1`` document is not valid."""


class NoConsistentWorld(UnstackError):
    """Hard evidence (probabilities of exactly 0 or 1) admits no transitive world.

    Attributes
    ----------
    conflict : list of tuple
        The relations in conflict, as ``(supporter, supported, value)`` triples: the
        forced chain (value 1) and the forbidden relation it implies (value 0).
    """

    def __init__(self, message: str, conflict: list[tuple[str, str, int]]) -> None:
        self.conflict = conflict
        super().__init__(message)


class TooLarge(UnstackError):
    """A scene is beyond what the requested method can do in reasonable time or memory."""


class NumericalRangeError(UnstackError):
    """The probabilities are so extreme that a float64 computation would lose them."""


class ModelRequired(UnstackError):
    """Deciding on a scene file needs a learned support model, which is not available."""
