"""The paper's "real" setting (§V-A2) rebuilt in simulation: piles of 7 boxes of four sizes.

For every pile, every ISet of ``r`` of its 7 boxes (r = 3, 4, 5: 35, 35 and 21 ISets) is
decided by unstack (with a model trained on simulated 10-20-box piles of the same four
sizes) and by a random decision maker. Reported per r: the share of ISets whose first pick
has the minimum possible cost, and MSE(cost) of Eq. 14; the paper's figures are 90.5 %,
81 % and 62 % right, and a worst MSE(cost) of 0.5 against 3.5 for random.

Examples
--------
>>> PAPER_REAL7["first_pick_right"]
{3: 0.905, 4: 0.81, 5: 0.62}
"""

from __future__ import annotations

import itertools
import os
import warnings
from collections.abc import Callable, Sequence
from typing import Any

from unstack.errors import UnstackError
from unstack.experiments.decisions import DECISION_MAKERS, decision_scores, iset_outcome
from unstack.parameters import OPTIONAL_COUNT, validate_params

__all__ = ["PAPER_FIRST_PICK_RIGHT", "PAPER_REAL7", "real7", "summary_rows"]

PAPER_FIRST_PICK_RIGHT = {3: 0.905, 4: 0.81, 5: 0.62}
#: The boxes of each pile in the paper's real setting (Section V-A2).
PAPER_PILE = 7
PAPER_REAL7: dict[str, Any] = {"first_pick_right": PAPER_FIRST_PICK_RIGHT, "worst_mse": {"unstack": 0.5, "random": 3.5}}


@validate_params({"piles": OPTIONAL_COUNT})
def real7(
    data_dir: str | os.PathLike[str],
    model: Any,
    *,
    sizes: Sequence[int] = (3, 4, 5),
    piles: int | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> dict[str, Any]:
    """Score every ISet of each r of every pile's boxes (all boxes of the pile, as the paper);
    ``piles`` limits the number of piles (the first ones)."""
    from unstack.dataset_folders import require_configurations
    from unstack.scene import load_scene

    files = require_configurations(data_dir)
    scenes = [load_scene(path) for path in files[:piles]]
    total = sum(len(list(itertools.combinations(scene.box_ids, r))) for scene in scenes for r in sizes)
    if total == 0:
        raise UnstackError(f"{data_dir}: no pile has {min(sizes)} boxes or more; nothing to decide on")
    other = [scene for scene in scenes if len(scene.box_ids) != PAPER_PILE]
    if other:
        warnings.warn(
            f"{data_dir}: {len(other)} of {len(scenes)} piles are not of the paper's {PAPER_PILE} boxes (the first "
            f"has {len(other[0].box_ids)}): their figures are not the paper's Section V-A2 setting",
            stacklevel=2,
        )
    done = 0
    per_size: dict[str, Any] = {}
    for r in sizes:
        results = []
        for scene in scenes:
            for ids in itertools.combinations(scene.box_ids, r):
                results.append(iset_outcome(scene, list(ids), model))
                done += 1
                if progress is not None:
                    progress(done, total)
        scores = {maker: decision_scores(results, maker) for maker in DECISION_MAKERS}
        per_size[str(r)] = {
            "isets": len(results),
            **{
                maker: {  # None where the piles hold no ISet of r boxes
                    "first_pick_right": float(values["first_pick_right"].mean()) if results else None,
                    "mse_cost": float(values["squared_regret"].mean()) if results else None,
                    "boxes_moved": float(values["moved"].mean()) if results else None,
                }
                for maker, values in scores.items()
            },
            "paper_first_pick_right": PAPER_FIRST_PICK_RIGHT.get(r),
        }
    worst = {
        maker: max((per_size[str(r)][maker]["mse_cost"] for r in sizes if per_size[str(r)]["isets"]), default=None)
        for maker in DECISION_MAKERS
    }
    return {"data": str(data_dir), "piles": len(scenes), "by_r": per_size, "worst_mse": worst, "paper": PAPER_REAL7}


def summary_rows(result: dict[str, Any]) -> list[list[str]]:
    """Rows for a table: r, ISets, paper, unstack, highest, random."""
    rows = []
    for r, values in result["by_r"].items():
        paper = values["paper_first_pick_right"]
        rows.append(
            [
                r,
                str(values["isets"]),
                f"{100 * paper:.1f} %" if paper is not None else "-",
                *(
                    "-"
                    if values[maker]["first_pick_right"] is None
                    else f"{100 * values[maker]['first_pick_right']:.1f} %"
                    for maker in ("reasoner", "highest", "random")
                ),
            ]
        )
    return rows
