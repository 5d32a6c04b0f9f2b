"""Threads for the compiled kernels: a lock for numba's ``parallel=True`` kernels, and
:func:`map_on_threads` for the GIL-free ones.

numba's default threading layer may fall back to ``workqueue``, which is documented as
unsafe when two Python threads enter parallel kernels at once (the process can abort).
Rather than choosing a threading layer -- a process-wide setting that belongs to the host
application -- every call into a parallel kernel of unstack holds :data:`PARALLEL_KERNELS`.
The kernels use all cores anyway, so serialising them costs no throughput; the Python work
around them (loading files, features, building results) still runs concurrently.

The exact walk's subtrees are a plain ``nogil`` function instead, run on threads the call
owns (:func:`map_on_threads`): no threading layer, no lock, and 26 s of compilation in a
fresh process instead of 61 s. The sampler keeps numba's parallel loop: its many short
calls ran 20 % slower on threads started per call (measured on plans of 31-40 boxes).

Examples
--------
>>> with PARALLEL_KERNELS:
...     pass
>>> map_on_threads(lambda item: item * item, range(4))
[0, 1, 4, 9]
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Sequence
from concurrent.futures import ThreadPoolExecutor
from typing import TypeVar

__all__ = ["PARALLEL_KERNELS", "map_on_threads"]

_Result = TypeVar("_Result")

#: Held for the duration of every call into a ``parallel=True`` numba kernel (re-entrant).
PARALLEL_KERNELS = threading.RLock()


def map_on_threads(function: Callable[[int], _Result], items: Sequence[int]) -> list[_Result]:
    """``[function(item) for item in items]``, on as many threads as numba may use.

    For functions that spend their time in ``nogil`` kernels. The results come back in the
    order of ``items``, so sums over them do not depend on scheduling. numba's thread count
    (``NUMBA_NUM_THREADS``, or ``numba.set_num_threads`` in the calling thread) is respected;
    one thread, or one item, runs in the calling thread. When an item fails (or the caller
    is interrupted), the items not yet started are cancelled and the error is raised.
    """
    from numba import get_num_threads

    threads = min(get_num_threads(), len(items))
    if threads <= 1:
        return [function(item) for item in items]
    pool = ThreadPoolExecutor(max_workers=threads, thread_name_prefix="unstack-kernel")
    try:
        futures = [pool.submit(function, item) for item in items]
        return [future.result() for future in futures]
    finally:  # an error or Ctrl-C: the items not started are dropped, not run to the end
        pool.shutdown(wait=True, cancel_futures=True)
