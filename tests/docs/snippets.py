"""Read the code blocks of the docs pages: ``python`` blocks and ``console`` commands."""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

FENCE = re.compile(r"^```(\w+)\n(.*?)^```", re.MULTILINE | re.DOTALL)
EXPECTED_EXIT = re.compile(r"#\s*exits with code (\d+)\s*$")


@dataclass(frozen=True)
class Snippet:
    page: str
    language: str
    code: str
    expected_exit: int = 0

    @property
    def name(self) -> str:
        first = self.code.strip().splitlines()[0]
        return f"{self.page}:{first[:50]}"


def snippets(docs: Path, language: str) -> list[Snippet]:
    """Every ``python`` block, or every ``$ command`` line of the ``console`` blocks."""
    found: list[Snippet] = []
    for page in sorted(docs.glob("*.md")):
        for block_language, body in FENCE.findall(page.read_text()):
            if block_language != language:
                continue
            if language == "python":
                found.append(Snippet(page.name, language, body))
                continue
            for line in body.splitlines():
                if line.startswith("$ "):
                    command = line[2:]
                    match = EXPECTED_EXIT.search(command)
                    exit_code = int(match.group(1)) if match else 0
                    found.append(Snippet(page.name, language, command, exit_code))
    return found
