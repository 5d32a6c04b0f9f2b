"""unstack: which carton box should a robot unload first?

Learn P(box X supports box Y), build the distribution over consistent possible worlds
(support is transitive) and pick the box of minimum expected cost.

A planner uses it in-process:

>>> import unstack
>>> supports = unstack.Supports(
...     ["top", "middle", "bottom"],
...     [[0.0, 0.05, 0.02], [0.9, 0.0, 0.1], [0.8, 0.95, 0.0]],
... )
>>> decision = unstack.decide(supports)
>>> decision.choice
'top'
"""

from __future__ import annotations

import os
from typing import Union

from unstack.errors import UnstackError
from unstack.jsonio import read_document, validate_document
from unstack.reasoner.decision import Decision, decide
from unstack.scene import Box, Scene, load_scene
from unstack.supports import Supports, load_supports

__all__ = [
    "Box",
    "Decision",
    "Scene",
    "Supports",
    "UnstackError",
    "__version__",
    "decide",
    "load",
    "load_scene",
    "load_supports",
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
