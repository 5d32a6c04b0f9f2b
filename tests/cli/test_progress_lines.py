"""Progress of long work in a pipe or a log: a plain line now and then, none for quick work."""

from __future__ import annotations

import pytest

from unstack.cli import progress
from unstack.cli.progress import progress_bar


def test_quick_work_in_a_log_writes_nothing(capsys: pytest.CaptureFixture[str]) -> None:
    with progress_bar("planning: steps") as report:
        for done in range(1, 6):
            report(done, 5)
    assert capsys.readouterr().err == ""


def test_long_work_in_a_log_says_where_it_is(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    clock = iter([0.0, 10.0, 31.0, 40.0, 62.5])
    monkeypatch.setattr(progress.time, "monotonic", lambda: next(clock))
    report = progress._log_lines("planning: steps")
    for done in range(1, 5):
        report(done, 200)
    assert capsys.readouterr().err.splitlines() == [
        "planning: steps 2 of 200 after 31 s",
        "planning: steps 4 of 200 after 62 s",
    ]
