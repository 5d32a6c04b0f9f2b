"""Dependencies point one way: the reasoner and ``unstack decide`` never load heavy parts."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

pytestmark = pytest.mark.slow  # imports the CLI in fresh interpreters

# scipy is not on the list: numba imports it at start-up whenever it is installed (its version
# check in numba/__init__.py), and the learning part depends on it. The reasoner's own code must
# still not import it (checked below).
HEAVY = ("sklearn", "pybullet", "matplotlib", "dask", "torch")

PROBE = """
import json, sys
sys.argv = ["unstack", "decide", {file!r}, "--json", "--method", {method!r}]
if {text!r}:
    sys.argv.remove("--json")
from unstack.cli.main import main
try:
    main()
except SystemExit:
    pass
sys.stderr.write(json.dumps(sorted(sys.modules)))
"""


@pytest.mark.parametrize("text", [False, True], ids=["json", "text"])
@pytest.mark.parametrize("method", ["exact", "sat"])
def test_decide_on_a_supports_file_imports_nothing_heavy(repo: Path, method: str, text: bool) -> None:
    # the text output says "support model: none": saying it must not load the model table's module
    probe = PROBE.format(file=str(repo / "examples" / "stack5.supports.json"), method=method, text=text)
    result = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, timeout=300, check=True)
    modules = json.loads(result.stderr.splitlines()[-1])
    if text:
        assert "Unload first: top_left" in result.stdout
    else:
        assert json.loads(result.stdout)["choice"] == "top_left"
    loaded = {name.split(".")[0] for name in modules}
    assert not loaded & set(HEAVY), sorted(loaded & set(HEAVY))
    assert "unstack.learning" not in modules


def test_importing_the_reasoner_loads_no_learning_or_simulation(repo: Path) -> None:
    code = "import sys, unstack.reasoner; print(' '.join(sorted(sys.modules)))"
    modules = set(
        subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.split()
    )
    assert not {name.split(".")[0] for name in modules} & set(HEAVY)
    assert "unstack.learning" not in modules and "unstack.sim" not in modules


def test_a_small_decision_loads_only_what_it_needs(repo: Path) -> None:
    """``unstack decide FILE --json`` on five boxes: no compiled engine, SAT solver, schema library or tables."""
    probe = PROBE.format(file=str(repo / "examples" / "stack5.supports.json"), method="auto", text=False)
    result = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, timeout=300, check=True)
    loaded = {name.split(".")[0] for name in json.loads(result.stderr)}
    lean = {"numba", "pysat", "networkx", "jsonschema", "rich", "scipy", *HEAVY}
    assert not loaded & lean, sorted(loaded & lean)
    assert "unstack.learning" not in json.loads(result.stderr)


@pytest.mark.parametrize("arguments", [["--help"], ["train", "--help"], ["experiment", "--help"]])
def test_help_lists_the_commands_without_loading_heavy_parts(arguments: list[str]) -> None:
    """Listing the commands imports each lazy command's module; none of them may load scikit-learn."""
    probe = PROBE.replace(
        '["unstack", "decide", {file!r}, "--json", "--method", {method!r}]', repr(["unstack", *arguments])
    ).replace("{text!r}", "False")
    result = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, timeout=300, check=True)
    loaded = {name.split(".")[0] for name in json.loads(result.stderr)}
    assert "Usage: unstack" in result.stdout
    assert not loaded & set(HEAVY), sorted(loaded & set(HEAVY))
