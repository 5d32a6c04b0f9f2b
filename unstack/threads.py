"""Threads for the compiled kernels: :func:`map_on_threads` runs GIL-free (``nogil``) kernels on
threads the call owns, and :func:`thread_count` says how many.

unstack uses no ``parallel=True`` kernel and so never starts numba's threading layer: choosing
or starting one is a process-wide act that belongs to the host application. Starting it has
effects a planner would notice -- it fixes the default start method of :mod:`multiprocessing`
(a later ``multiprocessing.set_start_method("spawn")`` fails), and the OpenMP layer's workers
spin while they wait, so that every parallel loop waited for a descheduled thread when another
process kept a core busy: a 31-box plan took 1.4-2.1 s instead of 0.45 s with the sampler in
such a loop, against 0.8-0.9 s on threads of its own (``benchmarks/busy_core.py``). The exact
walk's subtrees, the sampler's chains and the point-cloud counts are plain ``nogil`` kernels
over a range of their work, one range per thread; the results do not depend on the number of
threads (each chain and each query is computed whole by one thread, and results are combined
in a fixed order).

Examples
--------
>>> map_on_threads(lambda item: item * item, range(4))
[0, 1, 4, 9]
>>> even_ranges(10, 3)
[(0, 3), (3, 6), (6, 10)]
>>> squares = [0] * 5
>>> run_in_ranges(lambda first, last: squares.__setitem__(slice(first, last), [i * i for i in range(first, last)]), 5)
>>> squares
[0, 1, 4, 9, 16]
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from concurrent.futures import ThreadPoolExecutor
from typing import TypeVar

__all__ = ["even_ranges", "map_on_threads", "run_in_ranges", "thread_count"]

_Result = TypeVar("_Result")


def thread_count() -> int:
    """Threads a call may use, read without starting numba's threading layer.

    ``NUMBA_NUM_THREADS`` (every core by default); when the host application has started
    numba's threading layer, numba's setting for the calling thread
    (``numba.set_num_threads``).
    """
    import numba
    from numba.np.ufunc import parallel

    if getattr(parallel, "_is_initialized", False):  # numba's own flag: the host started the layer
        return int(numba.get_num_threads())
    return int(numba.config.NUMBA_NUM_THREADS)  # type: ignore[attr-defined]


def even_ranges(items: int, parts: int) -> list[tuple[int, int]]:
    """``parts`` contiguous ranges ``(first, last)`` covering ``range(items)``, as even as can be
    (fewer when there are fewer items)."""
    parts = max(1, min(parts, items))
    bounds = [items * k // parts for k in range(parts + 1)]
    return [(bounds[k], bounds[k + 1]) for k in range(parts)]


def map_on_threads(function: Callable[[int], _Result], items: Sequence[int]) -> list[_Result]:
    """``[function(item) for item in items]``, on :func:`thread_count` threads at most.

    For functions that spend their time in ``nogil`` kernels. The results come back in the
    order of ``items``, so sums over them do not depend on scheduling. One thread, or one
    item, runs in the calling thread. When an item fails (or the caller is interrupted), the
    items not yet started are cancelled and the error is raised.
    """
    threads = min(thread_count(), len(items))
    if threads <= 1:
        return [function(item) for item in items]
    pool = ThreadPoolExecutor(max_workers=threads, thread_name_prefix="unstack-kernel")
    try:
        futures = [pool.submit(function, item) for item in items]
        return [future.result() for future in futures]
    finally:  # an error or Ctrl-C: the items not started are dropped, not run to the end
        pool.shutdown(wait=True, cancel_futures=True)


def run_in_ranges(kernel: Callable[[int, int], object], items: int) -> None:
    """``kernel(first, last)`` for :func:`even_ranges` of ``items``, one range per thread of
    :func:`thread_count` (for ``nogil`` kernels that write each item's result in place)."""
    ranges = even_ranges(items, thread_count())
    map_on_threads(lambda part: kernel(*ranges[part]), range(len(ranges)))
