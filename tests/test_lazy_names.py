"""The subpackages that load their public names on first use: the stub lists each, each resolves."""

from __future__ import annotations

import ast
import importlib
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "unstack"


@pytest.mark.parametrize("package", ["reasoner", "learning"])
def test_every_name_of_the_stub_resolves_to_the_module_it_names(package: str) -> None:
    module = importlib.import_module(f"unstack.{package}")
    tree = ast.parse((PACKAGE / package / "__init__.pyi").read_text(encoding="utf-8"))
    homes = {
        alias.name: f"unstack.{package}.{node.module}"
        for node in tree.body
        if isinstance(node, ast.ImportFrom)
        for alias in node.names
    }
    assert sorted(homes) == sorted(module.__all__)
    for name, home in homes.items():
        assert getattr(module, name) is getattr(importlib.import_module(home), name)
    assert set(module.__all__) <= set(dir(module))


def test_an_unknown_name_is_an_attribute_error() -> None:
    import unstack.reasoner

    with pytest.raises(AttributeError, match=r"No unstack\.reasoner attribute nothing_here"):
        unstack.reasoner.nothing_here  # noqa: B018
