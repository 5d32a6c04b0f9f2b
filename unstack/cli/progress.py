"""A rich progress bar for long commands, on stderr (stdout is for results and JSON)."""

from __future__ import annotations

import sys
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager

from rich.console import Console

__all__ = ["LOG_EVERY", "progress_bar"]

#: Seconds between two progress lines in a pipe or a log.
LOG_EVERY = 30.0


def _log_lines(description: str, every: float = LOG_EVERY) -> Callable[[int, int], None]:
    """``report(done, total)`` that prints a line to stderr when ``every`` seconds have passed
    since the start or the last line."""
    start = last = time.monotonic()

    def report(done: int, total: int) -> None:
        nonlocal last
        now = time.monotonic()
        if now - last >= every:
            last = now
            print(f"{description} {done:,} of {total:,} after {now - start:.0f} s", file=sys.stderr, flush=True)

    return report


@contextmanager
def progress_bar(description: str) -> Iterator[Callable[[int, int], None]]:
    """Yield ``report(done, total)``; the bar (with ETA) disappears when the block ends.

    Drawn only when standard error is a terminal; in a pipe or a log, long work says where it
    is in a plain line at most every :data:`LOG_EVERY` seconds (``planning: steps 12 of 200
    after 41 s``), and work done sooner writes nothing.
    """
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TimeRemainingColumn

    console = Console(stderr=True)
    if not console.is_terminal:
        yield _log_lines(description)
        return
    with Progress(
        f"[progress.description]{description}",
        BarColumn(),
        MofNCompleteColumn(),
        "ETA",
        TimeRemainingColumn(),
        console=console,
        transient=True,
    ) as bar:
        task = bar.add_task(description, total=None)
        yield lambda done, total: bar.update(task, completed=done, total=total)
