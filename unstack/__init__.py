"""unstack: which carton box should a robot unload first?

Learn P(box X supports box Y), build the distribution over consistent possible worlds
(support is transitive) and pick the box of minimum expected cost.

A planner uses it in-process, from a scene (the default model gives the probabilities):

>>> import unstack
>>> decision = unstack.decide(unstack.load("examples/pile5.scene.json"))
>>> decision.choice in decision.objects
True

or from support probabilities it computed itself:

>>> supports = unstack.Supports(
...     ["top", "middle", "bottom"],
...     [[0.0, 0.05, 0.02], [0.9, 0.0, 0.1], [0.8, 0.95, 0.0]],
... )
>>> decision = unstack.decide(supports)
>>> decision.choice
'top'
>>> unstack.plan(supports).order
['top', 'middle', 'bottom']

The whole public API: :func:`load`, :func:`load_scene`, :func:`load_supports`,
:func:`load_model`, :func:`support_probabilities`, :func:`decide`, :func:`plan`,
:func:`validate`, and the types :class:`Box`, :class:`Scene`, :class:`Supports`,
:class:`Decision`, :class:`Plan`, :class:`UnstackError`, :class:`InvalidArgument`.
Importing it loads neither scikit-learn nor numba: they load when first needed.
"""

from __future__ import annotations

import os
from typing import Union

from unstack.api import decide, load_model, plan, support_probabilities
from unstack.errors import InvalidArgument, UnstackError
from unstack.jsonio import read_document, validate_document
from unstack.reasoner.decision import Decision
from unstack.reasoner.plan import Plan
from unstack.scene import Box, Scene, load_scene
from unstack.supports import Supports, load_supports
from unstack.validation import validate

__all__ = [
    "Box",
    "Decision",
    "InvalidArgument",
    "Plan",
    "Scene",
    "Supports",
    "UnstackError",
    "__version__",
    "decide",
    "load",
    "load_model",
    "load_scene",
    "load_supports",
    "plan",
    "support_probabilities",
    "validate",
]

__version__ = "0.1.0"


def load(path: str | os.PathLike[str]) -> Union[Supports, Scene]:  # noqa: UP007
    """Read any unstack document, dispatching on its ``format`` tag.

    Parameters
    ----------
    path : str or path-like
        A ``unstack.supports/1`` or ``unstack.scene/1`` file, or ``"-"`` for stdin.

    Returns
    -------
    Supports or Scene

    Raises
    ------
    InvalidFile
        Unreadable, not JSON, another format, or against the schema (names the file and
        the JSON path).

    Examples
    --------
    >>> import pathlib, tempfile
    >>> file = pathlib.Path(tempfile.mkdtemp()) / "pair.json"
    >>> Supports(["a", "b"], [[0, 0.3], [0.6, 0]]).save(file)
    >>> type(load(file)).__name__
    'Supports'
    """
    document = read_document(path)
    tag = validate_document(document, ["unstack.supports/1", "unstack.scene/1"])
    if tag == "unstack.scene/1":
        return Scene.from_document(document)
    return Supports.from_document(document)
