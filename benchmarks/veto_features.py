"""Can what the robot sees, without physics, tell when the physics veto will veto?

The physics veto (``unstack decide --physics-veto``, the container maker ``hybrid_faces_free``)
is the best policy built on what the robot sees, and the slowest. A fast stand-in would need
to tell, from the pick features of :mod:`unstack.learning.pick_features` (the robot's view and
the reasoner's marginals and expected costs), which picks the belief expects to move a box.

``collect OUT PILE...`` empties each pile (scene files of ``unstack simulate``) in the closed
loop with that maker, every seen box detected, and saves one file per pile in ``OUT``: the pick
features of every candidate of every state, which candidate was the reasoner's pick and which
was taken, and the belief's expected moves of the boxes it tried (NaN elsewhere). Resumable.

``report OUT`` reads them and prints, held out by pile (5 grouped folds):

* how often the pick was vetoed (expected to move at least one box);
* the shipped disturbance model's expected moves of the pick as a score of that verdict (ROC
  AUC, average precision) and a gradient-boosted classifier trained on the verdicts;
* for a gate that runs the physics only where the shipped model's score reaches a threshold:
  the share of vetoes it keeps and the share of states it sends to the physics engine.

Usage::

    python benchmarks/veto_features.py collect OUT d10-stacked/config-00*.json ...
    python benchmarks/veto_features.py report OUT
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
from pathlib import Path
from typing import Any

import numpy as np

#: Grouped folds of the held-out figures.
FOLDS = 5
#: The kept shares of vetoes the gate is reported at.
GATE_RECALLS = (0.9, 0.95, 0.98, 1.0)


def collect(out: Path, piles: list[Path]) -> None:
    """Empty each pile with the physics veto, saving what ``report`` reads (see the module)."""
    from unstack.experiments.container import CONTAINER_SAMPLES
    from unstack.height_veto import hybrid_choice
    from unstack.learning.model_file import default_model_path, load_model
    from unstack.learning.pick_features import pick_features
    from unstack.physics_veto import physics_veto
    from unstack.pipeline import scene_support_probabilities
    from unstack.reasoner.decision import decide
    from unstack.scene import Scene, load_scene
    from unstack.sim.unloading import in_view_scene, unload_container

    model = load_model(default_model_path())
    out.mkdir(parents=True, exist_ok=True)
    for path in piles:
        target = out / f"{path.parent.name}-{path.stem}.npz"
        if target.exists():
            continue
        states: list[dict[str, Any]] = []

        def policy(scene: Scene, states: list[dict[str, Any]] = states) -> str:
            supports = scene_support_probabilities(scene, model)
            reasoned = decide(supports, cost="load", samples=CONTAINER_SAMPLES, seed=0)
            pick = hybrid_choice(scene, reasoned)
            world_scene = in_view_scene(scene)
            vetoed = physics_veto(dataclasses.replace(reasoned, choice=pick), scene, seed=0, world_scene=world_scene)
            record = vetoed.physics_veto
            assert record is not None  # physics_veto always records what it tried
            tried = {item["box"]: item["expected_moved"] for item in record["tried"]}
            objects = list(supports.objects)
            states.append({
                "features": pick_features(scene, supports, reasoned.marginals, reasoned.expected_costs),
                "pick": objects.index(pick),
                "choice": objects.index(str(vetoed.choice)),
                "belief": np.array([tried.get(box_id, np.nan) for box_id in objects]),
            })  # fmt: skip
            return str(vetoed.choice)

        run = unload_container(load_scene(path), policy, seed=0)
        sizes = [len(state["belief"]) for state in states]
        np.savez(
            target,
            features=np.concatenate([state["features"] for state in states]),
            is_pick=np.concatenate([np.arange(n) == state["pick"] for n, state in zip(sizes, states, strict=True)]),
            is_choice=np.concatenate([np.arange(n) == state["choice"] for n, state in zip(sizes, states, strict=True)]),
            belief=np.concatenate([state["belief"] for state in states]),
        )
        print(f"{target}: {len(states)} states, {run.boxes_moved} boxes moved", flush=True)


def report(out: Path) -> int:
    """Print the held-out figures of the collected states (see the module)."""
    from sklearn.ensemble import HistGradientBoostingClassifier
    from sklearn.metrics import average_precision_score, roc_auc_score
    from sklearn.model_selection import GroupKFold

    from unstack.learning.disturbance import load_disturbance_model

    files = sorted(out.glob("*.npz"))
    if len(files) < FOLDS:
        print(f"veto_features.py: error: {out}: {len(files)} piles collected, {FOLDS} needed", file=sys.stderr)
        return 2
    moves_model = load_disturbance_model(None)
    features, vetoed, groups, families = [], [], [], []
    for number, path in enumerate(files):
        with np.load(path) as data:
            pick = data["is_pick"]
            features.append(data["features"][pick])
            vetoed.append(data["belief"][pick] >= 1.0)
        groups += [number] * int(pick.sum())
        families += [path.name.split("-")[1]] * int(pick.sum())
    x, y, group, family = np.concatenate(features), np.concatenate(vetoed), np.array(groups), np.array(families)
    shipped = moves_model.expected_moves(x)
    learned = np.zeros(len(y))
    for train, test in GroupKFold(FOLDS).split(x, y, group):
        classifier = HistGradientBoostingClassifier(max_iter=200, learning_rate=0.05, random_state=0)
        learned[test] = classifier.fit(x[train], y[train]).predict_proba(x[test])[:, 1]
    print(f"{len(files)} piles, {len(y)} states; the pick vetoed in {int(y.sum())} ({y.mean():.1%})")
    for name in np.unique(family):
        share = family == name
        print(f"  {name}: {int(share.sum())} states, {int(y[share].sum())} vetoed")
    for label, score in (("the shipped moves model", shipped), ("a classifier of the verdicts, held out", learned)):
        auc, precision = roc_auc_score(y, score), average_precision_score(y, score)
        print(f"{label}: ROC AUC {auc:.3f}, average precision {precision:.3f}")
    ordered = np.sort(shipped[y])
    for recall in GATE_RECALLS:
        threshold = ordered[int(np.floor((1.0 - recall) * len(ordered)))]
        kept, sent = (shipped[y] >= threshold).mean(), (shipped >= threshold).mean()
        print(f"gate at shipped expected moves >= {threshold:.3f}: keeps {kept:.0%} of vetoes, physics in {sent:.0%}")
    return 0


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    commands = parser.add_subparsers(dest="command", required=True)
    collecting = commands.add_parser("collect")
    collecting.add_argument("out", type=Path)
    collecting.add_argument("piles", nargs="+", type=Path)
    reporting = commands.add_parser("report")
    reporting.add_argument("out", type=Path)
    arguments = parser.parse_args(argv)
    if arguments.command == "collect":
        collect(arguments.out, arguments.piles)
        return 0
    return report(arguments.out)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
