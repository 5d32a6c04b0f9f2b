"""Support probabilities between detected boxes: the ``unstack.supports/1`` format.

This is what the reasoner consumes and what a planner with its own classifier hands in:
``probabilities[i, j] = P(SUPP(objects[i], objects[j]))``, row supports column, diagonal 0.

Examples
--------
>>> from unstack.supports import Supports
>>> supports = Supports(["a", "b"], [[0, 0.9], [0.05, 0]])
>>> supports.probability("a", "b")
0.9
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from unstack.atomic import atomic_write_text
from unstack.checks import (
    HEIGHT_RANGE,
    MAX_MASS,
    REFUSED_HIDDEN_LOAD,
    check_ids,
    check_metadata,
    check_probability_matrix,
    check_vector,
)
from unstack.errors import InvalidSupports
from unstack.frozen import read_only, set_frozen_fields
from unstack.jsonio import Document, read_document, validate_document

__all__ = ["SUPPORTS_FORMAT", "Supports", "load_supports"]

SUPPORTS_FORMAT = "unstack.supports/1"


def _refuse_first(vector: np.ndarray, bad: np.ndarray, source: str, path: str, expected: str) -> None:
    """Raise at the first entry of ``vector`` where ``bad`` holds: ``path[k]: expected ..., got value``."""
    rows = np.flatnonzero(bad)
    if rows.size:
        raise InvalidSupports(source, f"{path}[{rows[0]}]", f"expected {expected}, got {vector[rows[0]]:g}")


@dataclass(frozen=True, eq=False)
class Supports:
    """Pairwise support probabilities of ``n`` detected boxes.

    Parameters
    ----------
    objects : sequence of str
        Unique box ids; the order of the matrix rows and columns.
    probabilities : array-like, shape (n, n)
        ``P(SUPP(objects[i], objects[j]))``; 0 and 1 are hard evidence; diagonal 0.
    masses : array-like, shape (n,), optional
        Box masses in kg, for the mass-weighted cost.
    hidden_load : array-like, shape (n,), optional
        Expected number of *undetected* boxes resting on each box (what the point cloud
        shows on it that no detected box explains; see :mod:`unstack.understanding.hidden_load`). The
        ``load`` cost counts it; 0 when not given.
    heights : array-like, shape (n,), optional
        The height each box rests at: its lowest point above the floor in metres (a scene's
        boxes give it). With it, near ties in expected cost go to the box resting highest
        (:data:`~unstack.reasoner.decision.NEAR_TIE_MARGIN`); without it, the minimum EC (Eq. 12).
    metadata : dict, optional
        Free-form provenance, kept when saving.
    source : str, optional
        Where the values came from (a file name), used in error messages.

    Examples
    --------
    >>> Supports(["top", "bottom"], [[0, 0.1], [0.8, 0]]).n_objects
    2
    """

    objects: tuple[str, ...]
    probabilities: np.ndarray
    masses: np.ndarray | None
    metadata: dict[str, Any]
    source: str
    hidden_load: np.ndarray | None
    heights: np.ndarray | None

    def __init__(
        self,
        objects: Sequence[str],
        probabilities: Any,
        masses: Any = None,
        metadata: dict[str, Any] | None = None,
        source: str = "<array>",
        *,
        hidden_load: Any = None,
        heights: Any = None,
    ) -> None:
        ids = check_ids(objects, source=source)
        matrix = read_only(check_probability_matrix(probabilities, len(ids), source=source), probabilities)
        mass_vector = None
        if masses is not None:
            mass_vector = check_vector(
                masses, len(ids), positive=True, source=source, path="$.masses", error=InvalidSupports
            )
            _refuse_first(
                mass_vector, mass_vector > MAX_MASS, source, "$.masses", f"at most {MAX_MASS:,.0f} kg (a carton; kg?)"
            )
            mass_vector = read_only(mass_vector, masses)
        load_vector = None
        if hidden_load is not None:
            load_vector = check_vector(
                hidden_load, len(ids), source=source, path="$.hidden_load", error=InvalidSupports
            )
            _refuse_first(load_vector, load_vector < 0, source, "$.hidden_load", "a non-negative number")
            _refuse_first(
                load_vector,
                load_vector > REFUSED_HIDDEN_LOAD,
                source,
                "$.hidden_load",
                f"at most {REFUSED_HIDDEN_LOAD:,.0f} boxes",
            )
            load_vector = read_only(load_vector, hidden_load)
        height_vector = None
        if heights is not None:
            height_vector = check_vector(heights, len(ids), source=source, path="$.heights", error=InvalidSupports)
            low, high = HEIGHT_RANGE
            outside = (height_vector < low) | (height_vector > high)
            _refuse_first(height_vector, outside, source, "$.heights", f"a height from {low:g} to {high:g} m")
            height_vector = read_only(height_vector, heights)
        set_frozen_fields(
            self,
            hidden_load=load_vector,
            heights=height_vector,
            objects=ids,
            probabilities=matrix,
            masses=mass_vector,
            metadata=check_metadata(metadata, source=source, error=InvalidSupports),
            source=source,
        )

    def named(self, message: str) -> str:
        """``message`` led by the file these probabilities came from (as is for in-memory ones).

        Examples
        --------
        >>> Supports(["a"], [[0.0]], source="pile.json").named("31 boxes: too many")
        'pile.json: 31 boxes: too many'
        """
        return message if self.source in ("", "<array>") else f"{self.source}: {message}"

    @property
    def warnings(self) -> tuple[str, ...]:
        """The doubts about the input that the scene checks and the support model left in
        ``metadata["warnings"]``, one sentence each (none for probabilities given as such).

        Examples
        --------
        >>> Supports(["a", "b"], [[0, 0.5], [0.5, 0]], metadata={"warnings": ["a doubt"]}).warnings
        ('a doubt',)
        """
        found = self.metadata.get("warnings", [])
        if isinstance(found, str):
            return (found,)
        if not isinstance(found, list | tuple):
            return ()
        return tuple(str(item) for item in found)

    @property
    def n_objects(self) -> int:
        """Number of boxes."""
        return len(self.objects)

    def index(self, object_id: str) -> int:
        """Position of a box id in :attr:`objects`."""
        try:
            return self.objects.index(object_id)
        except ValueError:
            raise KeyError(f"unknown object id {object_id!r}") from None

    def probability(self, supporter: str, supported: str) -> float:
        """``P(SUPP(supporter, supported))`` as given (before the consistency step)."""
        return float(self.probabilities[self.index(supporter), self.index(supported)])

    def subset(self, object_ids: Sequence[str]) -> Supports:
        """The same probabilities restricted to (and reordered as) ``object_ids``.

        Examples
        --------
        >>> s = Supports(["a", "b", "c"], [[0, .5, .2], [.1, 0, .3], [.4, .6, 0]])
        >>> s.subset(["c", "a"]).probabilities.tolist()
        [[0.0, 0.4], [0.2, 0.0]]
        """
        order = [self.index(object_id) for object_id in object_ids]
        masses = None if self.masses is None else self.masses[order]
        load = None if self.hidden_load is None else self.hidden_load[order]
        heights = None if self.heights is None else self.heights[order]
        return Supports(
            list(object_ids),
            self.probabilities[np.ix_(order, order)],
            masses,
            self.metadata,
            self.source,
            hidden_load=load,
            heights=heights,
        )

    def to_dict(self) -> dict[str, Any]:
        """The ``unstack.supports/1`` JSON object."""
        data: dict[str, Any] = {
            "format": SUPPORTS_FORMAT,
            "objects": list(self.objects),
            "probabilities": self.probabilities.tolist(),
        }
        if self.masses is not None:
            data["masses"] = self.masses.tolist()
        if self.hidden_load is not None:
            data["hidden_load"] = self.hidden_load.tolist()
        if self.heights is not None:
            data["heights"] = self.heights.tolist()
        if self.metadata:
            data["metadata"] = self.metadata
        return data

    def save(self, path: str | os.PathLike[str]) -> None:
        """Write the ``unstack.supports/1`` file atomically."""
        from unstack.jsonio import document_text

        atomic_write_text(path, document_text(self.to_dict(), str(path)))

    @classmethod
    def from_document(cls, document: Document) -> Supports:
        """Build from a parsed, schema-checked document (semantic checks happen here)."""
        validate_document(document, [SUPPORTS_FORMAT], InvalidSupports)
        data = document.data
        return cls(
            data["objects"],
            data["probabilities"],
            data.get("masses"),
            data.get("metadata"),
            source=document.source,
            hidden_load=data.get("hidden_load"),
            heights=data.get("heights"),
        )


def load_supports(path: str | os.PathLike[str]) -> Supports:
    """Read an ``unstack.supports/1`` file (``"-"`` reads standard input).

    Raises
    ------
    InvalidFile
        With the file name, the JSON path and what was expected.

    Examples
    --------
    >>> import pathlib, tempfile
    >>> file = pathlib.Path(tempfile.mkdtemp()) / "pair.json"
    >>> Supports(["a", "b"], [[0, 0.9], [0.2, 0]]).save(file)
    >>> load_supports(file).objects
    ('a', 'b')
    """
    return Supports.from_document(read_document(path))
