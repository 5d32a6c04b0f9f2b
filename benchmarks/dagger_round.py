"""One DAgger round for the learned moves cost: how the shipped disturbance model fares on the
states its own policy reaches, and a model refitted on those states and the drawn ones together.

The states come from ``unstack experiment pick-responses``: some piles emptied by the drawn
behaviour (``--behaviour mixed``, the shipped model's training data) and the same piles, under
other data-set names, emptied by a policy that reads the model (``--behaviour
hybrid_moves_free_1``: the states the policy reaches itself). A pile's ``done.json`` says which.
Printed: the shipped model's calibration on each kind of state (Spearman's rank correlation,
means per predicted bin), then the refitted model's, held out with each physical pile's states
of both behaviours in the same fold (a pile is named by its family and configuration, so
``train-four/config-0003`` and ``dag-four/config-0003`` are one group). The refitted model is
saved as ``OUT/disturbance.skops`` with ``OUT/dagger.json``.

Usage::

    unstack experiment pick-responses train-four train-stacked train-mixed --out states
    ln -s train-four dag-four   # and stacked, mixed: the same piles under other names
    unstack experiment pick-responses dag-four dag-stacked dag-mixed --out states --behaviour hybrid_moves_free_1
    python benchmarks/dagger_round.py states --out dagger-model --jobs 2
    unstack experiment container f30-four --out R --piles 30 --jobs 1 --seed 0 --makers hybrid_moves_free_1 \\
        --disturbance dagger-model/disturbance.skops
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import Any

import numpy as np


def behaviours(states: Path) -> dict[str, str]:
    """``mixed`` or the decision maker that emptied each pile (``DATA-SET/PILE``) of ``states``."""
    return {
        f"{done.parent.parent.name}/{done.parent.name}": str(json.loads(done.read_text()).get("behaviour", "mixed"))
        for done in states.glob("*/*/done.json")
    }


def physical_pile(pile: str) -> str:
    """The pile whatever data-set name it was collected under: family and configuration."""
    from unstack.experiments.disturbance_training import family_of

    return f"{family_of(pile)}/{pile.split('/')[1]}"


def shipped_calibration(records: list[dict[str, Any]], states: Path) -> dict[str, Any]:
    """The shipped model's calibration on the rows of each behaviour and view."""
    from unstack.learning.disturbance import calibration, load_disturbance_model

    shipped = load_disturbance_model()
    behaviour = behaviours(states)
    kinds: dict[str, tuple[list[np.ndarray], list[np.ndarray]]] = {}
    for record in records:
        key = f"{behaviour[record['pile']]}/{record['view']}"
        predicted, actual = kinds.setdefault(key, ([], []))
        predicted.append(shipped.expected_moves(np.asarray(record["features"])))
        actual.append(np.asarray(record["moved"]))
    return {key: calibration(np.concatenate(p), np.concatenate(a)) for key, (p, a) in sorted(kinds.items())}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("states", type=Path, help="folder of collected states (both behaviours)")
    parser.add_argument("--out", type=Path, required=True, help="folder for disturbance.skops and dagger.json")
    parser.add_argument("--jobs", type=int, default=1)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--folds", type=int, default=5, help="grouped folds of the held-out figures")
    args = parser.parse_args()
    from unstack.experiments.disturbance_training import train_disturbance
    from unstack.experiments.pick_responses import pick_table
    from unstack.learning.disturbance import save_disturbance_model
    from unstack.learning.model_file import default_model_path, load_model

    if not any(args.states.glob("*/*/done.json")):
        print(f"dagger_round.py: error: {args.states}: no collected piles", file=sys.stderr)
        sys.exit(2)
    records = pick_table(args.states, load_model(default_model_path()), seed=args.seed, n_jobs=args.jobs)
    before = shipped_calibration(records, args.states)
    for key, table in before.items():
        bins = ", ".join(f"{row['mean_predicted']:.3f}/{row['mean_actual']:.3f}" for row in table["bins"])
        print(f"shipped model on {key}: {table['picks']} picks, Spearman {table['spearman']:.3f}; per bin {bins}")
    grouped = [dict(record, pile=physical_pile(record["pile"])) for record in records]
    model, report = train_disturbance(grouped, random_state=args.seed, folds=args.folds)
    model.metadata["training"] = {"states": str(args.states), "dagger": "drawn and on-policy states", "seed": args.seed}
    args.out.mkdir(parents=True, exist_ok=True)
    save_disturbance_model(model, args.out / "disturbance.skops")
    result = {"shipped_on_states": before, "refitted_held_out": report}
    (args.out / "dagger.json").write_text(json.dumps(result, indent=1) + "\n")
    print(f"refitted, held out ({report['piles']} piles, {report['rows']} picks): Spearman "
          f"{report['calibration']['spearman']:.3f}")  # fmt: skip
    for key, row in report["pick_scores"].items():
        print(f"  {key}: next pick moved, highest {row['highest']:.3f}, load {row['load']:.3f}, "
              f"moves {row['moves']:.3f}, look-ahead {row['lookahead']:.3f} ({row['states']} states)")  # fmt: skip


if __name__ == "__main__":
    main()
