"""The docs site builds with ``mkdocs build --strict`` and shows every schema field."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from tests.conftest import REPO

pytestmark = pytest.mark.slow  # builds the mkdocs site

SCHEMAS = sorted((REPO / "unstack" / "schemas").glob("*.schema.json"))


@pytest.fixture(scope="module")
def site(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("site")
    result = subprocess.run(
        [sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(out)],
        cwd=REPO,
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert result.returncode == 0, result.stdout + result.stderr
    return out


def test_every_page_is_built(site: Path) -> None:
    for page in ("quickstart", "formats", "reasoner", "simulation", "benchmarks", "reference"):
        assert (site / page / "index.html").is_file(), page


@pytest.mark.parametrize("schema_file", SCHEMAS, ids=lambda path: path.name)
def test_formats_page_lists_every_schema_field(site: Path, schema_file: Path) -> None:
    html = (site / "formats" / "index.html").read_text()
    schema = json.loads(schema_file.read_text())
    assert schema["title"] in html
    for field in schema["properties"]:
        assert f"$.{field}" in html, field


def test_the_simulation_page_shows_its_picture(site: Path) -> None:
    assert (site / "images" / "pile-paper2.png").is_file()
    assert "images/pile-paper2.png" in (site / "simulation" / "index.html").read_text()


def test_reference_page_renders_the_docstrings(site: Path) -> None:
    html = (site / "reference" / "index.html").read_text()
    assert "Choose the box to unload first" in html
    assert "NoConsistentWorld" in html


@pytest.mark.parametrize("name", ["decide"])
def test_the_reference_tables_signature_is_the_functions(name: str) -> None:
    """The table's decide listed 8 of its 12 parameters, and 'cost=...' for its default."""
    import inspect
    import re

    import unstack

    page = (REPO / "docs" / "reference.md").read_text()
    row = next(line for line in page.splitlines() if line.startswith(f"| `unstack.{name}("))
    listed = row.split("(", 1)[1].split(")`", 1)[0]
    written = dict(re.findall(r"(\w+)=([^,]+)", listed))
    parameters = inspect.signature(getattr(unstack, name)).parameters
    assert list(written) == [key for key in parameters if parameters[key].kind is inspect.Parameter.KEYWORD_ONLY]
    assert {key: repr(parameters[key].default).replace("'", '"') for key in written} == written
