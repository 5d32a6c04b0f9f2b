"""How often statics is right on simulated piles, and what it changes in the decisions.

For every pile of the given data sets (``unstack simulate`` folders, with removal labels) and
several detected sets per pile (every box, and random sets of 5 and 10), the leaning rule of
:mod:`unstack.understanding.statics` is run on the detected boxes. Each finding "X holds Y up" is checked
against the removal label (did Y move when X was taken away?): the share that holds is the
rule's precision, the figure :data:`unstack.understanding.statics.TIP_SUPPORT_PROBABILITY` stands for.
Then the default decision is made with and without statics, and the box each picks is
scored by the ground truth: how many boxes it really holds up (directly or not), and whether
it holds any.

Usage::

    python benchmarks/statics_precision.py DATA [DATA ...] --sets 3 --seed 0 --json out.json
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

from unstack.atomic import atomic_write_text
from unstack.learning.model_file import default_model_path, load_model
from unstack.pipeline import scene_support_probabilities
from unstack.reasoner.decision import decide
from unstack.scene import load_scene
from unstack.understanding.statics import TIP_SUPPORT_PROBABILITY, tip_supports


def _detected_sets(n: int, sets: int, rng: np.random.Generator) -> list[list[int]]:
    """Every box, then ``sets`` random sets of 5 and of 10 boxes."""
    chosen = [list(range(n))]
    for size in (5, 10):
        chosen += [sorted(rng.choice(n, min(n, size), replace=False).tolist()) for _ in range(sets)]
    return chosen


def _held_up(truth: np.ndarray, box: int) -> int:
    """Boxes that move when ``box`` is taken away (its row of the removal labels)."""
    return int(truth[box].sum())


def run_folder(folder: Path, model: Any, sets: int, rng: np.random.Generator) -> dict[str, Any]:
    findings = true = raised = raised_true = 0
    before: list[float] = []
    changed = picks = 0
    load = {"statics": 0, "model": 0}
    holding = {"statics": 0, "model": 0}
    for path in sorted(folder.glob("config-*.json")):
        scene = load_scene(path)
        truth = scene.ground_truth
        if truth is None:
            raise SystemExit(f"{path}: no removal labels (ground_truth.support)")
        ids = list(scene.box_ids)
        for detected in _detected_sets(len(ids), sets, rng):
            names = [ids[k] for k in detected]
            found = tip_supports(scene, names)
            plain = scene_support_probabilities(scene, model, boxes=names, statics=False)
            for finding in found:
                supporter, leaning = ids.index(finding.supporter), ids.index(finding.held)
                findings += 1
                true += int(truth[supporter, leaning])
                before.append(float(plain.probabilities[names.index(finding.supporter), names.index(finding.held)]))
                if before[-1] < TIP_SUPPORT_PROBABILITY:  # the pairs whose probability the rule raises
                    raised += 1
                    raised_true += int(truth[supporter, leaning])
            if not found:
                continue
            with_statics = scene_support_probabilities(scene, model, boxes=names)
            choices = {
                "statics": decide(with_statics, seed=0).choice,
                "model": decide(plain, seed=0).choice,
            }
            picks += 1
            changed += int(choices["statics"] != choices["model"])
            for key, choice in choices.items():
                moved = _held_up(truth, ids.index(choice))
                load[key] += moved
                holding[key] += int(moved > 0)
    return {
        "folder": str(folder),
        "findings": findings,
        "true": true,
        "precision": true / findings if findings else None,
        "mean_model_probability": float(np.mean(before)) if before else None,
        "raised": raised,
        "raised_true": raised_true,
        "decisions_with_findings": picks,
        "choices_changed": changed,
        "boxes_held_up_by_the_pick": load,
        "picks_holding_something": holding,
    }


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("folders", nargs="+", type=Path)
    parser.add_argument("--sets", type=int, default=3, help="random detected sets of 5 and of 10 per pile")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--json", type=Path, default=None)
    args = parser.parse_args(argv)
    model = load_model(default_model_path())
    rng = np.random.default_rng(args.seed)
    rows = []
    started = time.perf_counter()
    for folder in args.folders:
        row = run_folder(folder, model, args.sets, rng)
        rows.append(row)
        precision = "-" if row["precision"] is None else f"{row['precision']:.2f}"
        print(
            f"{folder.name}: {row['findings']} findings, {row['true']} true (precision {precision}, model's mean "
            f"P before {row['mean_model_probability'] or 0:.2f}; raised {row['raised']}, {row['raised_true']} of them "
            f"true); {row['decisions_with_findings']} decisions with "
            f"findings, {row['choices_changed']} choices changed; boxes held up by the pick, statics / model alone: "
            f"{row['boxes_held_up_by_the_pick']['statics']} / {row['boxes_held_up_by_the_pick']['model']}; "
            f"picks holding something {row['picks_holding_something']['statics']} / "
            f"{row['picks_holding_something']['model']}",
            flush=True,
        )
    total = {key: sum(row[key] for row in rows) for key in ("findings", "true", "raised", "raised_true")}
    print(
        f"all: {total['true']} of {total['findings']} findings true, {total['raised_true']} of the "
        f"{total['raised']} raised; {time.perf_counter() - started:.0f} s"
    )
    if args.json:
        atomic_write_text(args.json, json.dumps({"argv": argv, "rows": rows}, indent=2) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
