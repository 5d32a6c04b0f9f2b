"""Progress of long commands on stderr (stdout is for results and JSON): a rich bar on a
terminal, plain lines in a pipe or a log; rich is imported only for the bar."""

from __future__ import annotations

import sys
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager

__all__ = ["LOG_EVERY", "progress_bar", "still_working"]

#: Seconds between two progress lines in a pipe or a log.
LOG_EVERY = 30.0


@contextmanager
def _log_lines(
    description: str,
    every: float = LOG_EVERY,
    detail: Callable[[float], str | None] | None = None,
    within: Callable[[], str | None] | None = None,
) -> Iterator[Callable[[int, int], None]]:
    """Yield ``report(done, total)``; while the block runs, a line on stderr every ``every``
    seconds saying the latest count reported (none before the first report: ``description after
    N s``), so that work inside one long step says it is alive too; work done sooner writes nothing.
    ``detail(seconds)``, when it returns words, is the whole line instead; ``within()``, when it
    returns words, says where the step under way is, after the count.
    """
    start = time.monotonic()
    latest: list[tuple[int, int]] = []
    stop = threading.Event()

    def tick() -> None:
        while not stop.wait(every):
            seconds = time.monotonic() - start
            where = f" {latest[0][0]:,} of {latest[0][1]:,}" if latest else ""
            said = None if detail is None else detail(seconds)
            inside = None if within is None else within()
            step = f"; {inside}" if inside else ""
            try:
                print(said or f"{description}{where} after {seconds:.0f} s{step}", file=sys.stderr, flush=True)
            except (OSError, ValueError):  # stderr closed or gone: nothing more to say
                return

    def report(done: int, total: int) -> None:
        latest[:] = [(done, total)]

    thread = threading.Thread(target=tick, name="unstack-progress-lines", daemon=True)
    thread.start()
    try:
        yield report
    finally:
        stop.set()
        thread.join()


@contextmanager
def still_working(description: str, every: float = LOG_EVERY) -> Iterator[None]:
    """Work without steps (one decision, one picture) says it is alive: a line on stderr every
    :data:`LOG_EVERY` seconds (``deciding: still working after 30 s``), nothing for quick work;
    while the reasoner samples a group, where the sampling is (``deciding: sampling a group of
    40 boxes: 1,200,000 of 3,000,064 sweeps after 30 s; about 45 s to go for it``)."""
    from unstack.reasoner.progress import watching_sampling

    with watching_sampling() as sampling:

        def detail(seconds: float) -> str | None:
            where = sampling.line()
            if where is None:
                return None
            left = sampling.seconds_left()
            to_go = "" if left is None else f"; about {left:,.0f} s to go for it"
            return f"{description}: {where} after {seconds:.0f} s{to_go}"

        with _log_lines(f"{description}: still working", every, detail):
            yield


@contextmanager
def progress_bar(
    description: str, within: Callable[[], str | None] | None = None
) -> Iterator[Callable[[int, int], None]]:
    """Yield ``report(done, total)``; the bar (with ETA) disappears when the block ends.
    ``within()``, when it returns words, says where the step under way is (beside the bar, or
    after the count of a plain line): ``config-0003, lookahead: 12 picks, 21 boxes left``.

    Drawn only when standard error is a terminal; in a pipe or a log, long work says where it
    is in a plain line every :data:`LOG_EVERY` seconds (``planning: steps 12 of 200 after 41
    s``), within a long step too, and work done sooner writes nothing.
    """
    from rich.console import Console
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, ProgressColumn, TimeRemainingColumn
    from rich.text import Text

    console = Console(stderr=True)
    if not console.is_terminal:
        with _log_lines(description, within=within) as report:
            yield report
        return

    class Within(ProgressColumn):
        def render(self, task: object) -> Text:
            return Text((within() or "") if within is not None else "", style="progress.description")

    with Progress(
        f"[progress.description]{description}",
        BarColumn(),
        MofNCompleteColumn(),
        "ETA",
        TimeRemainingColumn(),
        Within(),
        console=console,
        transient=True,
    ) as bar:
        task = bar.add_task(description, total=None)
        yield lambda done, total: bar.update(task, completed=done, total=total)
