"""mkdocs hook: render the shipped JSON Schemas into the file-formats page.

A line ``<!-- schema: NAME -->`` in a page is replaced by a table of the schema's fields
(JSON path, type, required, description) followed by the schema itself, read from
``unstack/schemas/NAME.schema.json``: the page can never drift from the schemas that
``unstack validate`` uses.
"""

from __future__ import annotations

import json
import re
from pathlib import Path
from typing import Any

SCHEMAS = Path(__file__).resolve().parents[2] / "unstack" / "schemas"
MARKER = re.compile(r"^<!-- schema: ([\w.-]+) -->$", re.MULTILINE)


def _type_of(node: dict[str, Any]) -> str:
    if "const" in node:
        return f"`{json.dumps(node['const'])}`"
    if "enum" in node:
        return " or ".join(f"`{json.dumps(value)}`" for value in node["enum"])
    kind = node.get("type", "")
    if isinstance(kind, list):
        kind = " or ".join(kind)
    if kind == "array" and isinstance(node.get("items"), dict):
        inner = _type_of(node["items"])
        length = ""
        if node.get("minItems") is not None and node.get("minItems") == node.get("maxItems"):
            length = f"{node['minItems']} × "
        return f"array of {length}{inner}" if inner else "array"
    bounds = []
    if "minimum" in node:
        bounds.append(f"≥ {node['minimum']}")
    if "exclusiveMinimum" in node:
        bounds.append(f"> {node['exclusiveMinimum']}")
    if "maximum" in node:
        bounds.append(f"≤ {node['maximum']}")
    return f"{kind} ({', '.join(bounds)})" if bounds else str(kind)


def _rows(node: dict[str, Any], path: str, required: bool) -> list[str]:
    description = str(node.get("description", "")).replace("|", "\\|").replace("[", "\\[")
    rows = [f"| `{path}` | {_type_of(node)} | {'yes' if required else 'no'} | {description} |"]
    children = node.get("properties")
    if children is None and isinstance(node.get("items"), dict):
        children = node["items"].get("properties")
        needed = set(node["items"].get("required", []))
        path = f"{path}[]"
    else:
        needed = set(node.get("required", []))
    for name, child in (children or {}).items():
        rows += _rows(child, f"{path}.{name}", name in needed)
    return rows


def render_schema(name: str) -> str:
    """Markdown for one schema: a field table, then the schema in a collapsible block."""
    schema = json.loads((SCHEMAS / f"{name}.schema.json").read_text())
    header = ["| JSON path | type | required | meaning |", "|---|---|---|---|"]
    lines = [schema.get("description", "").replace("[", "\\["), "", *header]
    needed = set(schema.get("required", []))
    for field, node in schema.get("properties", {}).items():
        lines += _rows(node, f"$.{field}", field in needed)
    lines += ["", f'??? note "The schema file `unstack/schemas/{name}.schema.json`"', "", "    ```json"]
    lines += ["    " + line for line in json.dumps(schema, indent=2).splitlines()]
    lines += ["    ```", ""]
    return "\n".join(lines)


def on_page_markdown(markdown: str, **_: Any) -> str:
    """Replace every schema marker of a page by the rendered schema."""
    return MARKER.sub(lambda match: render_schema(match.group(1)), markdown)
