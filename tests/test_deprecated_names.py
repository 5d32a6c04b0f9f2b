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
