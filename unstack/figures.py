"""Deprecated name of :mod:`unstack.plotting` (renamed because it holds matplotlib plotting
without pyplot; pictures of scenes are :mod:`unstack.pictures`).

Importing it warns and gives the same names; the old name goes with version 0.2.
"""

import warnings

from unstack.plotting import *  # noqa: F403
from unstack.plotting import __all__  # noqa: F401

warnings.warn(
    "unstack.figures is renamed unstack.plotting; the old name goes with version 0.2",
    DeprecationWarning,
    stacklevel=2,
)
