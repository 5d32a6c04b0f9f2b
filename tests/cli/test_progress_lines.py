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


def test_a_sampled_decision_says_how_many_sweeps_of_how_many_and_the_time_left(
    capsys: pytest.CaptureFixture[str],
) -> None:
    import numpy as np

    import unstack

    rng = np.random.default_rng(3)
    probabilities = rng.uniform(0.0, 0.3, size=(12, 12))  # one linked group of 12: sampled
    np.fill_diagonal(probabilities, 0.0)
    supports = unstack.Supports([f"b{k}" for k in range(12)], probabilities)
    with progress.still_working("deciding", every=0.05):
        decision = unstack.decide(supports, samples=200_000, seed=0)
    lines = capsys.readouterr().err.splitlines()
    sampled = [line for line in lines if "sampling a group of 12 boxes" in line]
    assert sampled, lines
    assert re.fullmatch(
        r"deciding: sampling a group of 12 boxes: [\d,]+ of 200,\d{3} sweeps after \d+ s(; about [\d,]+ s to go for it)?",
        sampled[-1],
    )
    assert decision.to_dict() == unstack.decide(supports, samples=200_000, seed=0).to_dict()  # unwatched: the same


def test_a_long_pile_says_which_maker_empties_it_and_how_far(capsys: pytest.CaptureFixture[str]) -> None:
    from unstack.sim.progress import watching_picks

    with watching_picks() as picks, progress._log_lines("piles", every=0.05, within=picks.line) as report:
        report(0, 2)
        picks.pile("config-0000", "lookahead")
        picks.pick(12, 21)
        time.sleep(0.12)
    assert capsys.readouterr().err.splitlines()[-1] == (
        "piles 0 of 2 after 0 s; config-0000, lookahead: 12 picks, 21 boxes left"
    )
