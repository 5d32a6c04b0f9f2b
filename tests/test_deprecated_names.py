"""Renamed modules: the old name warns, names its successor and gives the same objects."""

from __future__ import annotations

import importlib
import sys

import pytest


@pytest.mark.parametrize(("old", "new"), [("datasets", "dataset_folders"), ("figures", "plotting")])
def test_an_old_module_name_warns_and_gives_the_same_names(old: str, new: str) -> None:
    sys.modules.pop(f"unstack.{old}", None)
    with pytest.warns(DeprecationWarning, match=rf"unstack\.{old} is renamed unstack\.{new}"):
        module = importlib.import_module(f"unstack.{old}")
    successor = importlib.import_module(f"unstack.{new}")
    assert module.__all__ == successor.__all__
    assert all(getattr(module, name) is getattr(successor, name) for name in successor.__all__)


@pytest.mark.parametrize(
    ("old", "new"),
    [
        ("Leaning", "TipSupport"),
        ("leaning_supports", "tip_supports"),
        ("raise_leaning_supports", "raise_tip_supports"),
        ("LEAN_SUPPORT_PROBABILITY", "TIP_SUPPORT_PROBABILITY"),
    ],
)
def test_an_old_statics_name_warns_and_is_the_new_one(old: str, new: str) -> None:
    from unstack.understanding import statics

    with pytest.warns(DeprecationWarning, match=rf"statics\.{old} is renamed {new}"):
        value = getattr(statics, old)
    assert value is getattr(statics, new)


def test_a_tip_support_still_answers_to_leaning_with_a_warning() -> None:
    from unstack.understanding.statics import TipSupport

    found = TipSupport("lean", "upright", 0.04, True)
    with pytest.warns(DeprecationWarning, match=r"TipSupport\.leaning is renamed TipSupport\.held"):
        assert found.leaning == "lean"


def test_insertion_sums_warns_and_changes_no_number() -> None:
    import numpy as np

    from unstack.reasoner.sampling import sampled_marginals

    probabilities = np.random.default_rng(3).uniform(0.0, 0.4, (12, 12))
    np.fill_diagonal(probabilities, 0.0)
    plain = sampled_marginals(probabilities, samples=512, seed=1)
    with pytest.warns(DeprecationWarning, match="insertion_sums was measured no better .* ignored"):
        asked = sampled_marginals(probabilities, samples=512, seed=1, insertion_sums=True)
    assert np.array_equal(asked.marginals, plain.marginals)
