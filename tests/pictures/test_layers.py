"""unstack.pictures sits on the data model: it imports no reasoner, learning, simulator, experiments or CLI."""

from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

ALLOWED = {
    "scene",
    "supports",
    "geometry",
    "plotting",
    "atomic",
    "frozen",
    "errors",
    "checks",
    "jsonio",
    "pictures",
}


def test_pictures_import_only_the_data_model(repo: Path) -> None:
    for path in (repo / "unstack" / "pictures").glob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            names = [alias.name for alias in node.names] if isinstance(node, ast.Import) else []
            if isinstance(node, ast.ImportFrom) and node.module:
                names = [node.module]
            for name in names:
                if name.startswith("unstack."):
                    assert name.split(".")[1] in ALLOWED, (path.name, name)


def test_importing_the_pictures_loads_no_plotting_library(repo: Path) -> None:
    code = "import sys, unstack, unstack.pictures; print(' '.join(sorted(sys.modules)))"
    modules = {name.split(".")[0] for name in subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True, cwd=repo
    ).stdout.split()}  # fmt: skip
    assert not modules & {"plotly", "matplotlib", "sklearn", "pybullet"}, sorted(modules & {"plotly", "matplotlib"})
