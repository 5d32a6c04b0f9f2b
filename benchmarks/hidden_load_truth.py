"""The hidden-load estimate against the simulator's removal ground truth, on ISets.

For the first ``--piles`` piles of each data set, ``--isets`` random ISets of ``--r`` detected
boxes are drawn (seeded by the pile's number); every box of an ISet is scored: the truth is
the number of boxes outside the ISet that it supports (removal ground truth), the estimate
:func:`unstack.understanding.hidden_load.hidden_load` with the ISet as the detected boxes. Printed per data
set: the Pearson correlation, the share of loaded boxes (truth at least 1) whose estimate is
above 0.5 and the share of unloaded boxes whose estimate is above 0.5 (false alarms).

Usage::

    python benchmarks/hidden_load_truth.py test30-stacked test30-wall paper-test30 --piles 10
"""

from __future__ import annotations

import numpy as np
from script_arguments import data_sets_parser, print_markdown_head

from unstack.dataset_folders import require_configurations
from unstack.scene import load_scene
from unstack.understanding.hidden_load import hidden_load


def score(data: str, piles: int, isets: int, r: int) -> dict[str, float]:
    """Correlation, share found and share of false alarms on one data set."""
    truth: list[float] = []
    estimate: list[float] = []
    for number, path in enumerate(require_configurations(data)[:piles]):
        scene = load_scene(path)
        supports = np.asarray(scene.ground_truth, dtype=float)
        ids = list(scene.box_ids)
        rng = np.random.default_rng(number)
        for _ in range(isets):
            iset = [str(box) for box in rng.choice(list(scene.detected), min(r, len(scene.detected)), replace=False)]
            others = [k for k, box in enumerate(ids) if box not in iset]
            truth.extend(supports[ids.index(box), others].sum() for box in iset)
            estimate.extend(hidden_load(scene, iset))
    real, guess = np.array(truth), np.array(estimate)
    loaded = real >= 1
    return {
        "boxes": float(len(real)),
        "loaded": float(loaded.sum()),
        "correlation": float(np.corrcoef(real, guess)[0, 1]),
        "found": float(np.mean(guess[loaded] > 0.5)),
        "false_alarms": float(np.mean(guess[~loaded] > 0.5)),
    }


def main() -> None:
    parser = data_sets_parser(__doc__.splitlines()[0], piles=10)
    parser.add_argument("--isets", type=int, default=3)
    parser.add_argument("--r", type=int, default=5)
    args = parser.parse_args()
    print_markdown_head("data set", "boxes (loaded)", "correlation", "loaded found", "false alarms")
    for data in args.data:
        row = score(data, args.piles, args.isets, args.r)
        print(
            f"| {data} | {row['boxes']:.0f} ({row['loaded']:.0f}) | {row['correlation']:.2f} | "
            f"{row['found'] * 100:.0f} % | {row['false_alarms'] * 100:.0f} % |",
            flush=True,
        )


if __name__ == "__main__":
    main()
