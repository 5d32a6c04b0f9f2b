"""Library warnings on the command line: one line each, said once."""

from __future__ import annotations

import pytest

from unstack.cli.main import _warning_line


def test_a_library_warning_is_printed_once_however_often_it_is_raised(capsys: pytest.CaptureFixture[str]) -> None:
    message = "d: 2 of the 30 configurations its manifest lists are finished (printed once)"
    for _ in range(3):
        _warning_line(message, UserWarning)
    assert capsys.readouterr().err.splitlines() == [f"unstack: warning: {message}"]


def test_different_warnings_are_each_printed_on_a_line_of_their_own(capsys: pytest.CaptureFixture[str]) -> None:
    messages = [f"box b{k} floats above the floor (each its own)" for k in range(3)]
    for message in messages:
        _warning_line(UserWarning(message), UserWarning)
    assert capsys.readouterr().err.splitlines() == [f"unstack: warning: {message}" for message in messages]
