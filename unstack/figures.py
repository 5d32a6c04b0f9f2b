"""Saving matplotlib figures: the Agg backend, and PNG files written atomically.

Examples
--------
>>> import pathlib, tempfile
>>> plt = pyplot()
>>> figure, axes = plt.subplots()
>>> target = pathlib.Path(tempfile.mkdtemp()) / "empty.png"
>>> save_png(figure, target)
>>> target.read_bytes()[:4]
b'\\x89PNG'
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

__all__ = ["pyplot", "save_png"]


def pyplot() -> Any:
    """``matplotlib.pyplot`` on the non-interactive Agg backend (no screen needed)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def save_png(figure: Any, output: str | os.PathLike[str], *, dpi: int = 110) -> None:
    """Write ``figure`` to a temporary file beside ``output``, rename it, and close the figure."""
    plt = pyplot()
    target = Path(output)
    temporary = target.with_name(f".{target.name}.tmp.png")
    try:
        figure.savefig(temporary, dpi=dpi)
        os.replace(temporary, target)
    finally:
        plt.close(figure)
        temporary.unlink(missing_ok=True)
