"""Where an experiment's piles run: local processes (joblib) or a dask.distributed cluster."""

from __future__ import annotations

from collections.abc import Callable, Iterator
from typing import Any


def run_unordered(
    function: Callable[..., Any], arguments: list[tuple[Any, ...]], *, n_jobs: int = 1, client: Any = None
) -> Iterator[Any]:
    """Call ``function(*task)`` for every task, yielding the results as they finish.

    Parameters
    ----------
    function : callable
        A module-level function (it is sent to other processes or to the workers).
    arguments : list of tuple
        The positional arguments of each call.
    n_jobs : int
        Local processes (joblib) when ``client`` is None.
    client : distributed.Client, optional
        Run the calls on the workers of this dask.distributed cluster instead.

    Yields
    ------
    object
        Each call's result, in the order the calls finish.

    Examples
    --------
    >>> sorted(run_unordered(pow, [(2, 3), (3, 2)]))
    [8, 9]
    """
    if client is not None:
        from distributed import as_completed

        futures = [client.submit(function, *task, pure=False) for task in arguments]
        for future in as_completed(futures, loop=client.loop):  # type: ignore[no-untyped-call]  # not the default client
            yield future.result()
        return
    from joblib import Parallel, delayed

    yield from Parallel(n_jobs=n_jobs, return_as="generator_unordered")(delayed(function)(*task) for task in arguments)
