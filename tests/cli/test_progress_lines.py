"""Progress of long work in a pipe or a log: a plain line now and then, none for quick work."""

from __future__ import annotations

import re
import time

import pytest

from unstack.cli import progress
from unstack.cli.progress import progress_bar


def test_quick_work_in_a_log_writes_nothing(capsys: pytest.CaptureFixture[str]) -> None:
    with progress_bar("planning: steps") as report:
        for done in range(1, 6):
            report(done, 5)
    assert capsys.readouterr().err == ""


def test_long_work_in_a_log_says_where_it_is_every_period_even_within_a_step(
    capsys: pytest.CaptureFixture[str],
) -> None:
    with progress._log_lines("planning: steps", every=0.05) as report:
        time.sleep(0.12)  # the first step is long: lines before any report
        report(2, 200)
        time.sleep(0.12)
    lines = capsys.readouterr().err.splitlines()
    assert re.fullmatch(r"planning: steps after 0 s", lines[0])
    assert re.fullmatch(r"planning: steps 2 of 200 after 0 s", lines[-1])


def test_work_without_steps_says_it_is_still_working(capsys: pytest.CaptureFixture[str]) -> None:
    with progress.still_working("deciding", every=0.05):
        time.sleep(0.12)
    assert capsys.readouterr().err.splitlines()[0] == "deciding: still working after 0 s"
