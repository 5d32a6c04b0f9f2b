"""The layers as a test: the import graph of ``unstack/``, read from the code, points one way.

Every ``import`` counts, at module level or inside a function (imports under
``if TYPE_CHECKING:`` count for the layers but not for cycles, since they never run).

- the data model (``scene``, ``supports``, formats, checks, errors, geometry, atomic
  writes, data-set folders, camera files, ... -- the modules directly under ``unstack/``) at the bottom;
- scene understanding (``understanding``: plausibility, statics, hidden load, clouds, the
  detector model) above it;
- ``reasoner``, ``learning``, ``sim`` and ``pictures`` above that, none importing another;
- the recipe scene -> probabilities (``pipeline``) above those;
- the public API (``unstack``, ``api``, ``describe``, ``height_veto``, ``moves``, ``physics_veto``, ``picture_inputs``,
  ``validation``, ``warmup``) above that;
- ``experiments`` above the API; ``cli`` on top.
"""

from __future__ import annotations

import ast
from dataclasses import dataclass
from pathlib import Path

import networkx as nx
import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "unstack"
MIDDLE = ("reasoner", "learning", "sim", "pictures")
API = {
    "unstack",
    "unstack.api",
    "unstack.describe",
    "unstack.height_veto",
    "unstack.moves",
    "unstack.physics_veto",
    "unstack.picture_inputs",
    "unstack.validation",
    "unstack.warmup",
}


@dataclass(frozen=True)
class ImportEdge:
    source: str
    target: str
    line: int
    runs: bool  # False for imports under ``if TYPE_CHECKING:``


def module_name(path: Path) -> str:
    parts = list(path.relative_to(PACKAGE.parent).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join(parts)


def type_checking_nodes(tree: ast.AST) -> set[int]:
    inside: set[int] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test):
            for statement in node.body:
                inside.update(id(child) for child in ast.walk(statement))
    return inside


def imported_names(node: ast.AST, module: str, is_package: bool) -> list[str]:
    if isinstance(node, ast.Import):
        return [alias.name for alias in node.names]
    if isinstance(node, ast.ImportFrom):
        base = node.module or ""
        if node.level:
            package = module.split(".") if is_package else module.split(".")[:-1]
            package = package[: len(package) - node.level + 1]
            base = ".".join([*package, base] if base else package)
        return [base, *(f"{base}.{alias.name}" for alias in node.names)]
    return []


def import_edges() -> list[ImportEdge]:
    modules = {module_name(path): path for path in PACKAGE.rglob("*.py")}
    edges = []
    for module, path in modules.items():
        tree = ast.parse(path.read_text(encoding="utf-8"))
        guarded = type_checking_nodes(tree)
        for node in ast.walk(tree):
            for target in imported_names(node, module, path.name == "__init__.py"):
                if target in modules and target != module:
                    edges.append(ImportEdge(module, target, getattr(node, "lineno", 0), id(node) not in guarded))
    return edges


def layer(module: str) -> tuple[int, str]:
    """``(level, group)``: a module may import its own group and any lower level."""
    parts = module.split(".")
    if module in API:
        return 4, "api"
    if len(parts) == 2 and parts[1] == "__main__":
        return 6, "cli"
    if len(parts) >= 2 and parts[1] == "understanding":
        return 1, "understanding"
    if len(parts) >= 2 and parts[1] in MIDDLE:
        return 2, parts[1]
    if len(parts) >= 2 and parts[1] == "pipeline":
        return 3, "pipeline"
    if len(parts) >= 2 and parts[1] == "experiments":
        return 5, "experiments"
    if len(parts) >= 2 and parts[1] == "cli":
        return 6, "cli"
    return 0, "data model"


def allowed(source: str, target: str) -> bool:
    (source_level, source_group), (target_level, target_group) = layer(source), layer(target)
    return target_level < source_level or source_group == target_group


EDGES = import_edges()


def test_the_graph_is_read_from_the_code_with_function_level_imports() -> None:
    pairs = {(edge.source, edge.target) for edge in EDGES}
    assert ("unstack.cli.main", "unstack.api") in pairs  # an import inside a function
    assert ("unstack.scene", "unstack.checks") in pairs  # a module-level import
    assert len(EDGES) > 100


@pytest.mark.parametrize(
    ("source", "target", "expected"),
    [
        ("unstack.learning.training_data", "unstack.sim.dataset", False),
        ("unstack.reasoner.decision", "unstack.learning.model_file", False),
        ("unstack.pictures.render", "unstack.reasoner.decision", False),
        ("unstack.scene", "unstack.api", False),
        ("unstack.learning.training_data", "unstack.dataset_folders", True),
        ("unstack.experiments.unloading", "unstack.sim.unloading", True),
        ("unstack.cli.main", "unstack.api", True),
        ("unstack.api", "unstack.cli.main", False),
        ("unstack.understanding.statics", "unstack.learning.features", False),
        ("unstack.scene", "unstack.understanding.plausibility", False),
        ("unstack.learning.training_data", "unstack.understanding.detector", True),
        ("unstack.learning.features", "unstack.pipeline", False),
        ("unstack.pipeline", "unstack.learning.features", True),
        ("unstack.pipeline", "unstack.understanding.statics", True),
        ("unstack.reasoner.decision", "unstack.pipeline", False),
    ],
)
def test_the_rule_tells_a_wrong_arrow_from_a_right_one(source: str, target: str, expected: bool) -> None:
    assert allowed(source, target) is expected


def test_no_import_points_against_the_layers() -> None:
    wrong = [f"{e.source} -> {e.target} (line {e.line})" for e in EDGES if not allowed(e.source, e.target)]
    assert not wrong, "\n".join(wrong)


def test_no_import_cycles() -> None:
    graph = nx.DiGraph((edge.source, edge.target) for edge in EDGES if edge.runs)
    cycles = list(nx.simple_cycles(graph))
    assert not cycles, cycles


def test_geometry_has_one_home() -> None:
    """Box corners, bounding boxes, rotation angles and footprint overlap are defined only in unstack.geometry."""
    homes: dict[str, list[str]] = {}
    for path in PACKAGE.rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.FunctionDef) and node.name.lstrip("_") in GEOMETRY:
                homes.setdefault(node.name.lstrip("_"), []).append(module_name(path))
    assert homes == {name: ["unstack.geometry"] for name in GEOMETRY}


#: Third-party packages a part of unstack must never import (at any depth of its own code).
FORBIDDEN_PACKAGES = {
    "reasoner": {"sklearn", "scipy", "pybullet", "skops", "matplotlib", "plotly", "dask"},
    "learning": {"pybullet", "dask", "plotly"},
    "pictures": {"sklearn", "pybullet", "dask"},
}


def third_party_imports(part: str) -> set[tuple[str, str]]:
    found = set()
    for path in (PACKAGE / part).rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            for name in imported_names(node, module_name(path), path.name == "__init__.py"):
                found.add((module_name(path), name.split(".")[0]))
    return found


@pytest.mark.parametrize("part", sorted(FORBIDDEN_PACKAGES))
def test_a_part_imports_none_of_its_forbidden_packages(part: str) -> None:
    wrong = sorted((module, top) for module, top in third_party_imports(part) if top in FORBIDDEN_PACKAGES[part])
    assert not wrong, wrong


GEOMETRY = ("box_corners", "bounding_boxes", "bounding_box_overlap_xy", "rotation_angles_deg", "footprint_overlap_area")


def test_the_data_model_takes_no_scene_understanding() -> None:
    """``scene`` refuses impossible input with the limits of ``checks`` and ``geometry``; it never
    imports ``plausibility``, which warns about scenes (the circle scene -> plausibility -> geometry -> scene)."""
    pairs = {(edge.source, edge.target) for edge in EDGES}
    assert ("unstack.scene", "unstack.understanding.plausibility") not in pairs
    assert ("unstack.scene", "unstack.checks") in pairs and (
        "unstack.understanding.plausibility",
        "unstack.checks",
    ) in pairs


def test_the_architecture_page_names_every_part_in_its_layer() -> None:
    """docs/architecture.md lists every module directly under ``unstack/`` and every subpackage."""
    page = (PACKAGE.parent / "docs" / "architecture.md").read_text(encoding="utf-8")
    table = page.split("| layer | modules |", 1)[1].split("\n\n", 1)[0]
    names = {path.stem for path in PACKAGE.glob("*.py") if path.stem != "__init__"} - {"__main__"}
    names |= {f"{path.name}/" for path in PACKAGE.iterdir() if (path / "__init__.py").exists()} - {"schemas/"}
    missing = sorted(name for name in names if f"`{name}`" not in table)
    assert not missing, missing
    rows = {line.split("|")[1].strip(): line for line in table.strip().splitlines()[1:]}
    for module in ("plausibility", "statics", "hidden_load", "clouds", "detector"):
        assert f"`{module}`" in rows["scene understanding"]
        assert (PACKAGE / "understanding" / f"{module}.py").exists()


def test_the_reasoner_takes_nothing_from_scene_understanding_or_the_pipeline() -> None:
    wrong = [
        f"{edge.source} -> {edge.target}"
        for edge in EDGES
        if edge.source.startswith("unstack.reasoner")
        and edge.target.startswith(("unstack.understanding", "unstack.pipeline"))
    ]
    assert not wrong, wrong
