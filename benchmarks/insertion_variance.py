"""How much a box's whole insertion, summed exactly, would take off the sampler's error.

The sampler records, for every pair, its relation's probability given every other relation
(:mod:`unstack.reasoner.sampling`). On classifier piles that is hardly better than the
world's own relations: where a box's row is tied to others by transitivity, the pair's
conditional is 0 or 1. :func:`unstack.reasoner.insertion.insertion_row_marginals` instead
averages over every way of putting the box back -- its row and column at once -- given the
rest of the world. For every pile of a data set (every box detected, the shipped model's
probabilities) this draws one chain of worlds, takes the ``--boxes`` noisiest boxes under the
sampler's record, and prints ``variance * autocorrelation time`` of each box's EC (the
sweeps needed for a standard error ``s`` are this over ``s**2``) for

* ``world``: the number of boxes it supports in the chain's world;
* ``pair``: the sampler's record (each pair given every other relation);
* ``insertion``: the exact insertion conditional;

and the time of one insertion sum against the core-time of one recorded sweep of the sampler
(from a 1-s run of it, which also gives the number of boxes whose EC has a standard error
above 0.008).

With ``--free-thresholds`` it measures instead the compiled sum the sampler records
(:mod:`unstack.reasoner.summed_insertions`): for each threshold, the box's free set (boxes
linked either way with a marginal of the chain at least the threshold), ``variance *
autocorrelation time`` of the cell average (the world's own row where the insertion leaves
the free set) recorded every sweep and every fourth sweep (times four: the same sweeps),
the share of worlds inside the cell, the slots of the dynamic programme and the time of one
sum.

Usage::

    unstack simulate --configs 8 --seed 7 --jobs 2 --out scenes40
    python benchmarks/insertion_variance.py scenes40 --worlds 1000 --boxes 3
    python benchmarks/insertion_variance.py scenes40 --worlds 1000 --boxes 3 --free-thresholds 0.01,0.03
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np
from numba import get_num_threads

sys.path.insert(0, str(Path(__file__).resolve().parent))

from intrinsic_variance import autocorrelation_time

from unstack.learning.model_file import default_model_path, load_model
from unstack.pipeline import scene_support_probabilities
from unstack.reasoner.insertion import insertion_row_marginals
from unstack.reasoner.sampling import sample_worlds, sampled_marginals
from unstack.scene import load_scene

#: A standard error above this leaves an error within 0.02 on every box to chance.
NOISY_ERROR = 0.008


def pair_conditionals(world: np.ndarray, probabilities: np.ndarray) -> np.ndarray:
    """The sampler's record of one world: ``p`` for a pair whose both values keep the world
    transitive, else the value transitivity leaves."""
    relation = world.copy()
    np.fill_diagonal(relation, False)
    present = relation.astype(np.int64)
    absent = (~relation).astype(np.int64)
    np.fill_diagonal(absent, 0)
    may_add = ((present.T @ absent) == 0) & ((absent @ present.T) == 0)  # supporters and supported kept
    may_drop = (present @ present) == 0  # no box in between
    record = np.where(may_add & may_drop, probabilities, np.where(may_add, 1.0, 0.0))
    np.fill_diagonal(record, 0.0)
    return record


def effort(series: np.ndarray) -> float:
    """``variance * autocorrelation time``: sweeps times the squared standard error."""
    return float(series.var() * autocorrelation_time(series))


def compiled_sums(dataset: Path, worlds_per_pile: int, boxes: int, seed: int, thresholds: str) -> int:
    """The ``--free-thresholds`` measurement (see the module docstring)."""
    from unstack.reasoner._insertion_sum_kernels import insertion_row, workspace
    from unstack.reasoner.summed_insertions import SUM_SLOTS, free_sets

    model = load_model(default_model_path())
    levels = [float(value) for value in thresholds.split(",")]
    empty = np.zeros(2, dtype=np.int64)
    insertion_row(0, np.int64(2), np.full((2, 2), 0.5), empty, empty, *workspace(2, 4), np.zeros(2))  # compile
    print(
        f"python benchmarks/insertion_variance.py {dataset} --worlds {worlds_per_pile} --boxes {boxes} "
        f"--free-thresholds {thresholds}"
    )
    for path in sorted(dataset.glob("config-*.json")):
        scene = load_scene(path)
        p = scene_support_probabilities(scene, model, boxes=list(scene.box_ids)).probabilities
        n = len(p)
        worlds = sample_worlds(p, worlds_per_pile, seed=seed)
        marginals = worlds.mean(axis=0)
        bits = np.left_shift(np.int64(1), np.arange(n, dtype=np.int64))
        successors = [np.array([bits[world[y] & (np.arange(n) != y)].sum() for y in range(n)]) for world in worlds]
        predecessors = [np.array([bits[world[:, y] & (np.arange(n) != y)].sum() for y in range(n)]) for world in worlds]
        recorded = np.array([pair_conditionals(world, p).sum(axis=1) for world in worlds])
        scratch = workspace(n, SUM_SLOTS)
        row = np.zeros(n)
        for box in sorted(range(n), key=lambda b: -effort(recorded[:, b]))[:boxes]:
            line = f"{path.stem} ({n} boxes) {scene.box_ids[box]}: pair {effort(recorded[:, box]):.1f}"
            for level in levels:
                free = free_sets(marginals, np.array([box]), threshold=level)[0]
                values, inside, slots = [], 0, []
                started = time.perf_counter()
                for world, succ, pred in zip(worlds, successors, predecessors, strict=True):
                    if insertion_row(box, free, p, succ, pred, *scratch, row):
                        values.append(row.sum())
                        inside += 1
                        slots.append(scratch[3][1])
                    else:
                        values.append(float(world[box].sum() - world[box, box]))
                seconds = (time.perf_counter() - started) / len(worlds)
                series = np.array(values)
                line += (
                    f" | {level}: {int(free).bit_count()} free, every sweep {effort(series):.2f}, every 4th "
                    f"{4 * effort(series[::4]):.2f}, inside {inside / len(worlds):.2f}, "
                    f"{np.mean(slots) if slots else 0:.0f} slots, {seconds * 1e6:.0f} us"
                )
            print(line, flush=True)
    return 0


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("dataset", type=Path)
    parser.add_argument("--worlds", type=int, default=1000, help="sweeps of the chain")
    parser.add_argument("--boxes", type=int, default=3, help="noisiest boxes per pile")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument(
        "--free-thresholds", default=None, help="comma-separated: measure the compiled sum over free sets instead"
    )
    args = parser.parse_args(argv)
    if args.free_thresholds is not None:
        return compiled_sums(args.dataset, args.worlds, args.boxes, args.seed, args.free_thresholds)
    model = load_model(default_model_path())
    print(f"python benchmarks/insertion_variance.py {args.dataset} --worlds {args.worlds} --boxes {args.boxes}")
    reductions, worst = [], []
    for path in sorted(args.dataset.glob("config-*.json")):
        scene = load_scene(path)
        p = scene_support_probabilities(scene, model, boxes=list(scene.box_ids)).probabilities
        worlds = sample_worlds(p, args.worlds, seed=args.seed)
        timing = sampled_marginals(p, time_limit=1.0, seed=args.seed)
        sweep_seconds = timing.seconds * get_num_threads() / timing.samples  # core-seconds, record included
        _, covariance = timing.errors_of(np.ones(len(p)))
        noisy = int(np.sum(np.sqrt(np.diag(covariance)) > NOISY_ERROR))
        print(
            f"{path.stem}: 1 s of the sampler recorded {timing.samples:,} sweeps; {noisy} boxes with a standard error "
            f"of their EC above {NOISY_ERROR}",
            flush=True,
        )
        own = worlds.sum(axis=2).astype(float)
        recorded = np.array([pair_conditionals(world, p).sum(axis=1) for world in worlds])
        noisiest = sorted(range(len(p)), key=lambda box: -effort(recorded[:, box]))[: args.boxes]
        pile = []
        for box in noisiest:
            started = time.perf_counter()
            summed = np.array([insertion_row_marginals(world, p, box).sum() for world in worlds])
            sum_seconds = (time.perf_counter() - started) / args.worlds
            row = (effort(own[:, box]), effort(recorded[:, box]), effort(summed))
            pile.append(row)
            reductions.append(row[1] / row[2])
            print(
                f"{path.stem} ({len(p)} boxes) {scene.box_ids[box]}: world {row[0]:.1f}  pair {row[1]:.1f}  "
                f"insertion {row[2]:.2f} ({row[1] / row[2]:.0f} times less); one sum {sum_seconds * 1e3:.0f} ms "
                f"= {sum_seconds / sweep_seconds:,.0f} sweeps",
                flush=True,
            )
        worst.append((max(row[1] for row in pile), max(row[2] for row in pile)))
    print(
        f"noisiest box of each pile: pair {', '.join(f'{a:.1f}' for a, _ in worst)}; insertion (of the same boxes) "
        f"{', '.join(f'{b:.2f}' for _, b in worst)}; median reduction {np.median(reductions):.0f} times "
        f"(range {min(reductions):.0f}-{max(reductions):.0f})"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
