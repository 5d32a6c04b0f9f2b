"""Boxes moved per pile by one maker against another, paired pile by pile, over several container runs.

Each argument is ``BASE:RUN``: two output folders of ``unstack experiment container`` on the same
piles (the same data set and seed); ``--base`` (default ``highest``) is read from ``BASE`` and
``--maker`` from ``RUN`` (they may be one folder). The piles both hold are paired; the paired
differences of every pair of folders are pooled, so several pile families give one figure.
Printed: piles, the two means, the mean difference +- its standard error, piles better / worse.

Usage::

    python benchmarks/paired_piles.py --maker belief_scaled_veto veto-f30-four:scaled-f30-four \\
        veto-f30-stacked:scaled-f30-stacked veto-f30-mixed:scaled-f30-mixed
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np


def boxes_moved(folder: Path, maker: str) -> dict[str, int]:
    """Boxes moved per pile (by checkpoint file name) of ``maker`` in a container run's folder."""
    moved = {}
    for path in sorted((folder / "container-piles").glob("*.json")):
        runs = json.loads(path.read_text())["result"]["runs"]
        if maker in runs:
            moved[path.name] = int(runs[maker]["boxes_moved"])
    if not moved:
        print(f"paired_piles.py: error: {folder}: no pile of maker {maker!r}", file=sys.stderr)
        sys.exit(2)
    return moved


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("pairs", nargs="+", help="BASE:RUN folders of unstack experiment container")
    parser.add_argument("--maker", required=True)
    parser.add_argument("--base", default="highest")
    arguments = parser.parse_args()
    base_values, run_values = [], []
    for pair in arguments.pairs:
        base_folder, _, run_folder = pair.partition(":")
        base = boxes_moved(Path(base_folder), arguments.base)
        run = boxes_moved(Path(run_folder or base_folder), arguments.maker)
        for pile in sorted(set(base) & set(run)):
            base_values.append(base[pile])
            run_values.append(run[pile])
    base_array, run_array = np.array(base_values, dtype=float), np.array(run_values, dtype=float)
    difference = run_array - base_array
    error = difference.std(ddof=1) / np.sqrt(len(difference)) if len(difference) > 1 else float("nan")
    print(
        f"{len(difference)} piles: {arguments.maker} {run_array.mean():.2f}, {arguments.base} {base_array.mean():.2f}; "
        f"paired difference {difference.mean():+.2f} +- {error:.2f}; better on {int((difference < 0).sum())}, "
        f"worse on {int((difference > 0).sum())}"
    )


if __name__ == "__main__":
    main()
