"""One lock for numba's ``parallel=True`` kernels: safe calls from several Python threads.

numba's default threading layer may fall back to ``workqueue``, which is documented as
unsafe when two Python threads enter parallel kernels at once (the process can abort).
Rather than choosing a threading layer -- a process-wide setting that belongs to the host
application -- every call into a parallel kernel of unstack holds :data:`PARALLEL_KERNELS`.
The kernels use all cores anyway, so serialising them costs no throughput; the Python work
around them (loading files, features, building results) still runs concurrently.

Examples
--------
>>> with PARALLEL_KERNELS:
...     pass
"""

from __future__ import annotations

import threading

__all__ = ["PARALLEL_KERNELS"]

#: Held for the duration of every call into a ``parallel=True`` numba kernel (re-entrant).
PARALLEL_KERNELS = threading.RLock()
