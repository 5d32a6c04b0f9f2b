"""Deprecated name of :mod:`unstack.dataset_folders` (renamed because it reads data-set folders;
the simulator writes them, :mod:`unstack.sim.dataset`).

Importing it warns and gives the same names; the old name goes with version 0.2.
"""

import warnings

from unstack.dataset_folders import *  # noqa: F403
from unstack.dataset_folders import __all__  # noqa: F401

warnings.warn(
    "unstack.datasets is renamed unstack.dataset_folders; the old name goes with version 0.2",
    DeprecationWarning,
    stacklevel=2,
)
