"""What the benchmark scripts over simulated data sets share: their arguments, table heads and
the default model's probabilities of their piles."""

from __future__ import annotations

import argparse
from collections.abc import Iterator
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import numpy as np

    from unstack.scene import Scene


def data_sets_parser(description: str, *, piles: int | None, several: bool = True) -> argparse.ArgumentParser:
    """A parser of one data set folder (``several``: one or more) and ``--piles`` (``None``: all)."""
    parser = argparse.ArgumentParser(description=description)
    if several:
        parser.add_argument("data", nargs="+", help="data set folders of unstack simulate")
    else:
        parser.add_argument("data", help="a data set folder of unstack simulate")
    parser.add_argument(
        "--piles", type=int, default=piles, help="the first N piles of each data set (default: %(default)s)"
    )
    return parser


def print_markdown_head(*columns: str, numbers_from: int | None = None) -> None:
    """Print a Markdown table's head; the columns from ``numbers_from`` on are right-aligned."""
    first = len(columns) if numbers_from is None else numbers_from
    print("| " + " | ".join(columns) + " |")
    print("|" + "|".join("---" if k < first else "---:" for k in range(len(columns))) + "|")


def pile_probabilities(folder: Path, piles: int | None = None) -> Iterator[tuple[Path, Scene, np.ndarray]]:
    """Each pile of a data set folder (the first ``piles``; all by default) with the shipped
    default model's support probabilities over all its boxes, detected or not."""
    from unstack.learning.model_file import default_model_path, load_model
    from unstack.pipeline import scene_support_probabilities
    from unstack.scene import load_scene

    model = load_model(default_model_path())
    for path in sorted(folder.glob("config-*.json"))[:piles]:
        scene = load_scene(path)
        yield path, scene, scene_support_probabilities(scene, model, boxes=list(scene.box_ids)).probabilities
