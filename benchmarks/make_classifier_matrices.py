"""Support matrices of simulated piles, as the shipped classifier sees them.

Writes ``benchmarks/data/classifier-matrices.npz``: one ``n x n`` matrix per configuration of
a data set (every box of the pile, in the scene's order), from
``unstack.learning.models/default-paper2.skops``. The benchmark family ``classifier`` of
:mod:`instances` reads it.

Usage::

    unstack simulate --configs 8 --seed 7 --jobs 2 --out scenes40
    python benchmarks/make_classifier_matrices.py scenes40
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
from script_arguments import pile_probabilities

OUTPUT = Path(__file__).resolve().parent / "data" / "classifier-matrices.npz"


def main(argv: list[str]) -> int:
    dataset = Path(argv[0])
    matrices = {}
    for path, scene, probabilities in pile_probabilities(dataset):
        matrices[path.stem] = probabilities
        print(f"{path.stem}: {len(scene.box_ids)} boxes")
    OUTPUT.parent.mkdir(exist_ok=True)
    np.savez_compressed(OUTPUT, **matrices)
    print(f"wrote {OUTPUT} ({OUTPUT.stat().st_size / 1024:.0f} KiB)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
