"""Learning support relations (§III-A): features, the classifier, evaluation, model files.

Imports neither pybullet nor the simulator at import time; reading training data from a
simulated data set folder uses only its JSON and ``.npy`` files.

Examples
--------
>>> from unstack.learning import FEATURE_NAMES
>>> len(FEATURE_NAMES)
19
"""

import lazy_loader

#: Public names load on first use (their modules are listed in ``__init__.pyi``, which static
#: tools read too), so importing a light part of the package does not import the heavy ones.
__getattr__, __dir__, __all__ = lazy_loader.attach_stub(__name__, __file__)
