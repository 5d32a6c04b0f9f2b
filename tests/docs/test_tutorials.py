"""The docs pages run as written: every python block and every console command."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from tests.conftest import REPO
from tests.docs.snippets import Snippet, snippets

pytestmark = pytest.mark.slow  # runs every command and code block of the docs

DOCS = REPO / "docs"
PYTHON_SNIPPETS = snippets(DOCS, "python")
CONSOLE_SNIPPETS = [s for s in snippets(DOCS, "console") if not s.code.startswith("pip ")]


def environment() -> dict[str, str]:
    """The test's interpreter first on PATH, so ``unstack`` is the installed command."""
    env = dict(os.environ)
    env["PATH"] = str(Path(sys.executable).parent) + os.pathsep + env.get("PATH", "")
    return env


def test_the_tutorials_have_code_to_run() -> None:
    pages = {s.page for s in PYTHON_SNIPPETS + CONSOLE_SNIPPETS}
    assert {"quickstart.md", "reasoner.md", "reference.md"} <= pages
    assert len(CONSOLE_SNIPPETS) >= 5


@pytest.mark.parametrize("snippet", PYTHON_SNIPPETS, ids=lambda s: s.name)
def test_python_block_runs(snippet: Snippet) -> None:
    result = subprocess.run(
        [sys.executable, "-c", snippet.code], cwd=REPO, capture_output=True, text=True, timeout=300, env=environment()
    )
    assert result.returncode == 0, result.stderr


CONSOLE_PAGES = sorted({snippet.page for snippet in CONSOLE_SNIPPETS})


@pytest.mark.parametrize("page", CONSOLE_PAGES)
def test_console_commands_run_in_order(page: str, tmp_path: Path) -> None:
    """A page's commands run one after the other in one folder, as a reader types them."""
    (tmp_path / "examples").symlink_to(REPO / "examples")
    for snippet in (s for s in CONSOLE_SNIPPETS if s.page == page):
        before = set(tmp_path.iterdir())
        result = subprocess.run(
            ["bash", "-c", f"set -o pipefail; {snippet.code}"],
            cwd=tmp_path,
            capture_output=True,
            text=True,
            timeout=300,
            env=environment(),
        )
        assert result.returncode == snippet.expected_exit, (snippet.code, result.stdout + result.stderr)
        if snippet.expected_exit:
            assert result.stderr.startswith("unstack: error: ") and result.stderr.count("\n") == 1
            assert "Traceback" not in result.stderr
        else:
            assert result.stdout or set(tmp_path.iterdir()) - before, snippet.code
