"""Library warnings on the command line: one line each, said once."""

from __future__ import annotations

import pytest

from unstack.cli.main import _warn, _warning_line


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


def test_a_warning_the_scene_and_its_decision_both_carry_is_printed_once(capsys: pytest.CaptureFixture[str]) -> None:
    scene_warning = "s.json: box 'top' floats (the scene's, and again the decision's)"
    _warn(scene_warning)
    _warning_line(scene_warning, UserWarning)
    _warn("s.json: out of distribution (the decision's only)")
    assert capsys.readouterr().err.splitlines() == [
        f"unstack: warning: {scene_warning}",
        "unstack: warning: s.json: out of distribution (the decision's only)",
    ]


def test_a_word_of_thousands_of_characters_is_cut_in_the_middle_with_its_length(
    capsys: pytest.CaptureFixture[str],
) -> None:
    path = "/tmp/" + "d" * 4000 + "/x.json"
    _warn(f"{path}: cannot write there")
    [line] = capsys.readouterr().err.splitlines()
    assert (
        len(line) < 300
        and line.startswith("unstack: warning: /tmp/ddd")
        and line.endswith("d/x.json: cannot write there")
    )
    assert f"…({len(path) + 1:,} characters)…" in line


@pytest.mark.parametrize(
    ("library", "command"),
    [
        ("they have not mixed; sample longer (samples=1024)", "they have not mixed; sample longer (--samples 1024)"),
        ("(samples=4096) and compare two seeds", "(--samples 4096) and compare two seeds"),
        ("give time_limit=2, seed=0", "give --time-limit 2, --seed 0"),
        ("the samples are 1024", "the samples are 1024"),
    ],
)
def test_a_library_warning_names_the_commands_options(
    library: str, command: str, capsys: pytest.CaptureFixture[str]
) -> None:
    """The library's warnings name its arguments (they named --samples to Python callers)."""
    from unstack.cli.main import _print_warnings

    _print_warnings((library,))
    assert capsys.readouterr().err == f"unstack: warning: {command}\n"
