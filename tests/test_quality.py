"""The repository's own rules: ruff and mypy clean, CI runs exactly the README's test command."""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import pytest


def run(repo: Path, *args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", *args], cwd=repo, capture_output=True, text=True, timeout=600)


@pytest.mark.slow
def test_ruff_is_clean(repo: Path) -> None:
    folders = [name for name in ("unstack", "tests", "benchmarks", "docs") if (repo / name).is_dir()]
    result = run(repo, "ruff", "check", *folders)
    assert result.returncode == 0, result.stdout + result.stderr


@pytest.mark.slow
def test_mypy_is_clean(repo: Path) -> None:
    result = run(repo, "mypy")
    assert result.returncode == 0, result.stdout + result.stderr


def readme_command(repo: Path, marker: str) -> str:
    lines = (repo / "README.md").read_text().splitlines()
    for index, line in enumerate(lines):
        if marker in line:
            return lines[index + 1].strip()
    raise AssertionError(f"README has no line after {marker!r}")


def test_ci_runs_exactly_the_readme_test_command(repo: Path) -> None:
    command = readme_command(repo, "<!-- test-command -->")
    assert command in (repo / ".ci" / "run").read_text().splitlines()


@pytest.mark.skipif(shutil.which("git") is None, reason="git not installed")
def test_readme_main_job_names_a_bundled_example(repo: Path) -> None:
    command = readme_command(repo, "<!-- main-job -->")
    example = command.split("unstack decide ", 1)[1].split()[0]
    assert (repo / example).is_file()


def test_the_readme_names_the_fast_lane_and_tests_carry_the_slow_marker(repo: Path) -> None:
    assert readme_command(repo, "<!-- fast-lane -->") == 'pytest -m "not slow"'
    marked = [path for path in (repo / "tests").rglob("test_*.py") if "pytest.mark.slow" in path.read_text()]
    assert len(marked) >= 20, marked


@pytest.mark.slow  # runs the main job in a subprocess
def test_the_readme_shows_what_the_main_job_prints_today(repo: Path) -> None:
    """The sample output under ``<!-- main-job-output -->`` is the main job's output, but for its seconds."""
    import re

    text = (repo / "README.md").read_text()
    block = text.split("<!-- main-job-output -->", 1)[1].split("```text\n", 1)[1].split("```", 1)[0]
    command = readme_command(repo, "<!-- main-job -->").split("&& unstack ", 1)[1].split()
    result = subprocess.run(
        [sys.executable, "-m", "unstack", *command], cwd=repo, capture_output=True, text=True, timeout=300
    )
    assert result.returncode == 0, result.stderr

    def canonical(output: str) -> list[str]:
        return [re.sub(r"\d+\.\d+ s$", "N s", line.rstrip()) for line in output.strip().splitlines()]

    assert canonical(result.stdout) == canonical(block)
