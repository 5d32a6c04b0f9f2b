"""Re-insertions per sweep in a group of up to 63 boxes: the error of a fixed time budget.

A sweep of the sampler is one Gibbs pass over the pairs, ``moves`` re-insertions (the next
boxes in turn) and the record of every pair's conditional. Fewer re-insertions make a sweep
cheaper, so more sweeps (and more pair passes and records) fit in the same time. This
benchmark runs every instance for ``--time-limit`` seconds with each value of
:data:`unstack.reasoner.sampling.MOVES` and compares the expected costs with a long reference
run of the sampler (its own standard error enters the coverage).

Instances (all seeded):

* ``classifier``: the support matrices of simulated 31-40-box piles shipped in
  ``benchmarks/data/classifier-matrices.npz`` (``--scenes DATASET`` adds the default model's
  matrices of every configuration of a data set made by ``unstack simulate``);
* ``weak``: 40 boxes in 8 dense groups of 5, every pair across ``1e-3`` or ``1e-2``
  (:func:`weak_links.weak_groups`);
* ``dense``: 24 boxes, every pair ``U(0.05, 0.95)`` (:func:`instances.instance`).

Usage::

    python benchmarks/narrow_moves.py --moves 63,16,8,4 --seeds 4 --time-limit 1 \\
        --json benchmarks/results/narrow-moves.json
"""

from __future__ import annotations

import argparse
import hashlib
import json
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from instances import instance
from weak_links import weak_groups

import unstack.reasoner.sampling as sampling
from unstack.atomic import atomic_write_text

DATA = Path(__file__).resolve().parent / "data" / "classifier-matrices.npz"


def instances(scenes: Path | None, scene_limit: int, shipped_limit: int) -> dict[str, np.ndarray]:
    """Every instance of the benchmark by name."""
    found: dict[str, np.ndarray] = {}
    with np.load(DATA) as shipped:
        for name in shipped.files[:shipped_limit]:
            found[f"classifier {name}"] = shipped[name]
    if scenes is not None:
        from large_scenes import scene_matrices

        for name, matrix in list(scene_matrices(scenes).items())[:scene_limit]:
            found[f"classifier {scenes.name}/{name}"] = matrix
    for link in (1e-3, 1e-2):
        found[f"weak 8x5 link {link:g}"] = weak_groups(8, 5, link, 0)
    found["dense 24"] = instance("dense", 24, 0)
    return found


def reference(p: np.ndarray, seconds: float, cache: Path | None) -> tuple[np.ndarray, np.ndarray]:
    """Expected costs and their standard errors from a long run with every box per sweep
    (kept in ``cache``, a folder, for the next run of the benchmark)."""
    key = None if cache is None else cache / f"{hashlib.sha1(p.tobytes()).hexdigest()[:16]}-{seconds:g}.npy"
    if key is not None and key.exists():
        costs, errors = np.load(key)
        return costs, errors
    sampling.MOVES = 64
    result = sampling.sampled_marginals(p, time_limit=seconds, seed=10_000)
    costs, covariance = result.errors_of(np.ones(len(p)))
    errors = np.sqrt(np.diag(covariance))
    if key is not None:
        key.parent.mkdir(parents=True, exist_ok=True)
        np.save(key, np.stack([costs, errors]))
    return costs, errors


def run(args: argparse.Namespace) -> list[dict[str, Any]]:
    rows = []
    default_moves = sampling.MOVES
    for name, p in instances(args.scenes, args.scene_limit, args.shipped_limit).items():
        n = len(p)
        sampling.sampled_marginals(p, samples=16, seed=0)  # load the compiled kernels
        truth, truth_errors = reference(p, args.reference_seconds, args.reference_cache)
        print(f"{name} ({n} boxes): reference s.e. up to {truth_errors.max():.4f}", flush=True)
        for seed in range(args.seeds):
            for moves in args.moves:
                sampling.MOVES = moves
                budget: dict[str, Any] = {"time_limit": args.time_limit}
                if args.sweeps:  # a fixed budget: the default's number of sweeps for each moves
                    budget = {"samples": sampling.default_samples(n)}
                start = time.perf_counter()
                result = sampling.sampled_marginals(p, seed=seed, **budget)
                seconds = time.perf_counter() - start
                costs, covariance = result.errors_of(np.ones(n))
                errors = np.sqrt(np.diag(covariance))
                deviation = np.abs(costs - truth)
                row = {
                    "instance": name,
                    "n": n,
                    "moves": moves,
                    "seed": seed,
                    "worst_ec_error": float(deviation.max()),
                    "coverage": float(np.mean(deviation <= 2 * np.sqrt(errors**2 + truth_errors**2))),
                    "samples": result.samples,
                    "acceptance": result.acceptance,
                    "seconds": seconds,
                    "reference_max_standard_error": float(truth_errors.max()),
                }
                rows.append(row)
                print(
                    f"  seed {seed} moves {moves:2d}: worst EC error {row['worst_ec_error']:.4f}, "
                    f"coverage {row['coverage']:.2f}, {result.samples} sweeps, {seconds:.2f} s",
                    flush=True,
                )
    sampling.MOVES = default_moves
    return rows


def summary(rows: list[dict[str, Any]], moves_list: list[int]) -> None:
    """Mean worst EC error per instance family and moves."""
    families = sorted({row["instance"].split(" ")[0] for row in rows})
    for family in families:
        for moves in moves_list:
            chosen = [r for r in rows if r["instance"].startswith(family) and r["moves"] == moves]
            worst = np.array([r["worst_ec_error"] for r in chosen])
            print(
                f"{family:10s} moves {moves:2d}: worst EC error median {np.median(worst):.4f}, "
                f"mean {worst.mean():.4f}, max {worst.max():.4f}; "
                f"coverage {np.mean([r['coverage'] for r in chosen]):.3f}; "
                f"sweeps {np.mean([r['samples'] for r in chosen]):.0f} ({len(chosen)} runs)"
            )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--moves", type=lambda text: [int(v) for v in text.split(",")], default=[64, 16, 8, 4])
    parser.add_argument("--seeds", type=int, default=4)
    parser.add_argument("--time-limit", type=float, default=1.0)
    parser.add_argument("--reference-seconds", type=float, default=30.0)
    parser.add_argument(
        "--sweeps", action="store_true", help="run the default budget of sweeps instead of --time-limit seconds"
    )
    parser.add_argument("--scenes", type=Path, default=None)
    parser.add_argument("--scene-limit", type=int, default=4)
    parser.add_argument("--shipped-limit", type=int, default=8, help="shipped classifier matrices to use")
    parser.add_argument("--reference-cache", type=Path, default=None, help="folder keeping the reference runs")
    parser.add_argument("--json", type=Path, default=None)
    args = parser.parse_args()
    rows = run(args)
    summary(rows, args.moves)
    if args.json is not None:
        atomic_write_text(args.json, json.dumps({"command": sys.argv, "rows": rows}, indent=1))


if __name__ == "__main__":
    main()
