"""Boxes moved per pile by one maker against another, paired pile by pile, over several container runs.

Each argument is ``BASE:RUN``: two output folders of ``unstack experiment container`` on the same
piles (the same data set and seed); ``--base`` (default ``highest``) is read from ``BASE`` and
``--maker`` from ``RUN`` (they may be one folder). The piles both hold are paired (a file name that holds
another scene or another detector miss rate in the two folders is refused, exit 2); the paired
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


def boxes_moved(folder: Path, maker: str) -> dict[str, tuple[tuple[str, float], int]]:
    """Boxes moved per pile of ``maker`` in a container run's folder, by checkpoint file name,
    each with what must match in a pair: the pile's scene hash and the detector's miss rate."""
    moved = {}
    for path in sorted((folder / "container-piles").glob("*.json")):
        checkpoint = json.loads(path.read_text())
        runs, key = checkpoint["result"]["runs"], checkpoint["key"]
        if maker in runs:
            pile = (str(key["scene_sha256"]), float(key.get("detector_misses", 0.0)))
            moved[path.name] = (pile, int(runs[maker]["boxes_moved"]))
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
            if base[pile][0] != run[pile][0]:
                print(
                    f"paired_piles.py: error: {pair}: {pile} is another pile or another detector in the two folders",
                    file=sys.stderr,
                )
                sys.exit(2)
            base_values.append(base[pile][1])
            run_values.append(run[pile][1])
    if not base_values:
        print("paired_piles.py: error: the folders share no pile of both makers", file=sys.stderr)
        sys.exit(2)
    base_array, run_array = np.array(base_values, dtype=float), np.array(run_values, dtype=float)
    difference = run_array - base_array
    spread = difference.std(ddof=1) / np.sqrt(len(difference)) if len(difference) > 1 else None
    error = f"+- {spread:.2f}" if spread is not None else "(one pile: no s.e.)"
    print(
        f"{len(difference)} piles: {arguments.maker} {run_array.mean():.2f}, {arguments.base} {base_array.mean():.2f}; "
        f"paired difference {difference.mean():+.2f} {error}; better on {int((difference < 0).sum())}, "
        f"worse on {int((difference > 0).sum())}"
    )


if __name__ == "__main__":
    main()
