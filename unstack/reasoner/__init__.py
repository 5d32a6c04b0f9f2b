"""The possible-worlds reasoner (§III-B, §III-C, §IV).

Turns pairwise support probabilities into the distribution over consistent (transitive)
worlds and picks the box of minimum expected cost. Imports neither scikit-learn nor
pybullet.

Examples
--------
>>> from unstack.supports import Supports
>>> from unstack.reasoner import decide
>>> decide(Supports(["a", "b"], [[0, 0.2], [0.7, 0]])).choice
'a'
"""

import lazy_loader

#: Public names load on first use (their modules are listed in ``__init__.pyi``, which static
#: tools read too), so importing a light part of the package does not import the heavy ones.
__getattr__, __dir__, __all__ = lazy_loader.attach_stub(__name__, __file__)
