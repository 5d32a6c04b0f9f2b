"""Collection rules for ``pytest benchmarks --benchmark-enable``.

The project's addopts include ``--doctest-modules``, which would import every script in
this folder as a test module; the scripts (``peers.py`` and the others) need optional
dependencies and are meant to be run as programs. Only the ``test_*.py`` suites and the
doctest of ``instances.py`` are collected here.
"""

from __future__ import annotations

from pathlib import Path

import pytest

COLLECTED_MODULES = {"instances.py"}


def pytest_ignore_collect(collection_path: Path, config: pytest.Config) -> bool | None:
    """Skip the scripts of this folder; keep ``test_*.py`` and :data:`COLLECTED_MODULES`."""
    if collection_path.suffix != ".py" or collection_path.parent != Path(__file__).parent:
        return None
    if collection_path.name.startswith("test_") or collection_path.name in COLLECTED_MODULES:
        return None
    if collection_path.name == "conftest.py":
        return None
    return True
