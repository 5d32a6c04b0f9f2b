"""Compile (or load from numba's cache) every compiled kernel before the first real call.

After a fresh install the first decision on a group of six or more boxes, the first
sampled group, the first group of 64 boxes or more and the first scene's features each pay
for numba's compilation (seconds to a minute each; the README states what was measured).
``unstack warm-up`` -- or :func:`warm_up` at a robot's start-up -- pays it once, and numba
caches the result on disk for later processes.

Examples
--------
>>> [name for name, _ in KERNELS][:2]
['exact engine', 'sampler']
"""

from __future__ import annotations

import contextlib
import threading
import time
from collections.abc import Callable, Iterator
from typing import Any

import numpy as np

__all__ = ["KERNELS", "announcing_compilation", "might_compile", "warm_up"]


def _exact() -> None:
    from unstack.reasoner.marginals import exact_marginals

    probabilities = np.full((6, 6), 0.5)
    np.fill_diagonal(probabilities, 0.0)
    exact_marginals(probabilities)


def _sampler() -> None:
    from unstack.reasoner.sampling import sample_worlds, sampled_marginals

    probabilities = np.full((9, 9), 0.3)
    np.fill_diagonal(probabilities, 0.0)
    sampled_marginals(probabilities, samples=16, seed=0, burn_in=1)
    sample_worlds(probabilities, 1, seed=0, burn_in=1)


def _wide_sampler() -> None:
    from unstack.reasoner.sampling import sampled_marginals

    probabilities = np.full((70, 70), 0.02)  # more boxes than one 64-bit word holds
    np.fill_diagonal(probabilities, 0.0)
    sampled_marginals(probabilities, samples=4, seed=0, burn_in=1)


def _features() -> None:
    from unstack.learning._contact_kernel import column_index, counts_in_boxes
    from unstack.learning._dbaf_kernel import gaussian_sums

    points = np.random.default_rng(0).uniform(0.0, 1.0, (64, 3))
    gaussian_sums(points, points[:4].copy(), 2.0)
    columns = column_index(points, 0.25)
    counts_in_boxes(columns, np.zeros((2, 3)), np.ones((2, 3)))


#: What :func:`warm_up` compiles, in order: ``(name, function)``.
KERNELS: tuple[tuple[str, Callable[[], None]], ...] = (
    ("exact engine", _exact),
    ("sampler", _sampler),
    ("wide sampler", _wide_sampler),
    ("feature kernels", _features),
)
#: Seconds each group takes to compile on an empty cache, one process after the other on a
#: 2-core machine with a core busy elsewhere (``NUMBA_CACHE_DIR=$(mktemp -d) python -c "from
#: unstack.warmup import KERNELS; dict(KERNELS)['sampler']()"``, timed): what the first call's
#: note says; processes start the longest first.
_COMPILE_SECONDS = {"exact engine": 13.6, "sampler": 11.4, "wide sampler": 12.6, "feature kernels": 2.0}


#: The module each kernel group's compiled functions live in (the sampler's module compiles both
#: its layouts: "sampler" and "wide sampler" warm up one each; :func:`_compiled_group` tells them
#: apart by the chains' arrays).
_MODULES = {
    "unstack.reasoner._insertion_kernels": "exact engine",
    "unstack.reasoner._sampler_kernels": "sampler",
    "unstack.learning._dbaf_kernel": "feature kernels",
    "unstack.learning._contact_kernel": "feature kernels",
}


def _compiled_group(function: Any, args: Any) -> str:
    """The kernel group a compilation belongs to: by the compiled function's module, and for the
    sampler by its chains' layout (successors of three dimensions: word-array sets, the wide sampler).

    Examples
    --------
    >>> import numba
    >>> from unstack.reasoner._chain_arrays import ChainArrays
    >>> from unstack.reasoner._sampler_kernels import run_chains
    >>> def chains(ndim):
    ...     sets = np.zeros((2,) * ndim, dtype=np.int64)
    ...     return numba.typeof(ChainArrays(sets, sets, *(np.zeros(2, dtype=np.int64),) * 3, np.zeros((2, 2, 2, 2))))
    >>> _compiled_group(run_chains.py_func, [chains(2)]), _compiled_group(run_chains.py_func, [chains(3)])
    ('sampler', 'wide sampler')
    """
    from unstack.reasoner._chain_arrays import ChainArrays

    group = _MODULES.get(getattr(function, "__module__", ""), "kernels")
    if group != "sampler":
        return group
    for argument in args or ():
        if getattr(argument, "instance_class", None) is ChainArrays and argument.types[0].ndim == 3:
            return "wide sampler"
    return group


def might_compile(boxes: int) -> bool:
    """Whether a decision on ``boxes`` boxes can call a compiled kernel at all.

    Groups of up to 5 linked boxes are counted in plain Python (no numba import); a scene
    with a model that reads the cloud may need the feature kernels whatever its size.

    Examples
    --------
    >>> might_compile(5), might_compile(6)
    (False, True)
    """
    return boxes > 5


@contextlib.contextmanager
def announcing_compilation(announce: Callable[[str], None]) -> Iterator[None]:
    """Call ``announce(sentence)`` once, the moment numba starts compiling a kernel inside the block.

    numba compiles a kernel on its first call in an environment whose on-disk cache does not
    hold it (a fresh install); loading a cached kernel announces nothing. The sentence names
    the kernel group, its compile time on one core (:data:`KERNELS`' measured seconds) and
    ``unstack warm-up``. The listener is numba's own (``numba.core.event``) and is removed
    when the block ends.

    Examples
    --------
    >>> heard = []
    >>> with announcing_compilation(heard.append):
    ...     _ = warm_up()
    >>> heard  # the suite's kernels are compiled already
    []
    """
    from numba.core import event

    lock = threading.Lock()
    told: list[str] = []

    class Listener(event.Listener):
        def on_start(self, started: Any) -> None:
            function = getattr(started.data.get("dispatcher"), "py_func", None)
            group = _compiled_group(function, started.data.get("args"))
            with lock:
                if told:
                    return
                told.append(group)
            seconds = _COMPILE_SECONDS.get(group)
            expected = f", about {seconds:.0f} s on one core" if seconds else ""
            announce(
                f"numba is compiling the {group} for first use in this environment (once{expected}; later "
                "calls load it from numba's cache); 'unstack warm-up' compiles every kernel at once"
            )

        def on_end(self, ended: Any) -> None:
            pass

    with event.install_listener("numba:compile", Listener()):
        yield


def warm_up(progress: Callable[[str, float], None] | None = None, *, jobs: int = 1) -> dict[str, float]:
    """Compile or load every kernel; report each one's seconds.

    Parameters
    ----------
    progress : callable, optional
        Called as ``progress(name, seconds)`` after each kernel (in the order they finish).
    jobs : int
        Processes compiling at once. numba compiles on one core, so on an empty cache
        ``jobs=2`` about halves the wait on two cores; the longest kernels start first.
        Each process writes numba's on-disk cache, which every later process loads.

    Returns
    -------
    dict
        Seconds per kernel name (near 0 once numba's cache holds them).

    Raises
    ------
    InvalidArgument
        ``jobs`` is not a positive integer.

    Examples
    --------
    >>> sorted(warm_up())
    ['exact engine', 'feature kernels', 'sampler', 'wide sampler']
    """
    from unstack.reasoner.arguments import check_count

    jobs = min(check_count(jobs, "jobs"), len(KERNELS))  # a process a group of kernels at most
    if jobs == 1:
        seconds = {}
        for name, _ in KERNELS:
            seconds[name] = _compile(name)
            if progress is not None:
                progress(name, seconds[name])
        return seconds
    return _warm_up_in_processes(progress, jobs)


def _compile(name: str) -> float:
    """Compile (or load) the kernels called ``name`` in :data:`KERNELS`; their seconds."""
    start = time.perf_counter()
    dict(KERNELS)[name]()
    return time.perf_counter() - start


def _warm_up_in_processes(progress: Callable[[str, float], None] | None, jobs: int) -> dict[str, float]:
    """:func:`warm_up` in ``jobs`` fresh processes (``spawn``: no thread state is inherited)."""
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor, as_completed

    names = sorted(dict(KERNELS), key=lambda name: -_COMPILE_SECONDS[name])
    seconds = {}
    with ProcessPoolExecutor(max_workers=jobs, mp_context=multiprocessing.get_context("spawn")) as pool:
        futures = {pool.submit(_compile, name): name for name in names}
        try:
            for future in as_completed(futures):
                seconds[futures[future]] = future.result()
                if progress is not None:
                    progress(futures[future], seconds[futures[future]])
        except KeyboardInterrupt:  # Ctrl-C, or the command line's SIGTERM: the workers end now, not after compiling
            for process in list(getattr(pool, "_processes", {}).values()):
                process.terminate()
            pool.shutdown(wait=False, cancel_futures=True)
            raise
    return {name: seconds[name] for name, _ in KERNELS}
