"""Re-insertions per sweep in a group of more than 63 boxes: error and time per budget.

One instance of 150 boxes (30 dense groups of 5, every pair across ``link``; seed 0), a
reference run of 32,768 sweeps, then runs of 1024 and 4096 sweeps (seed 1) with ``moves``
re-insertions per sweep (:data:`unstack.reasoner.sampling.WIDE_MOVES` is set for each).

With ``--pile N`` the instance is instead one strongly linked pile of ``N`` boxes (every pair
``U(0.001, 0.05)``, about 2 in ``N`` pairs ``U(0.5, 0.95)``; seed 5) and, without a reference,
each run of 2048 sweeps reports its largest R-hat and standard error.

Usage::

    NUMBA_NUM_THREADS=1 python benchmarks/wide_moves.py --link 1e-3 --moves 150,40,16
    NUMBA_NUM_THREADS=1 python benchmarks/wide_moves.py --pile 100 --moves 100,16
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from weak_links import weak_groups

import unstack.reasoner.sampling as sampling


def pile(n: int, moves_list: list[int]) -> None:
    """Largest R-hat, standard error and seconds of 2048 sweeps on one strongly linked pile."""
    rng = np.random.default_rng(5)
    p = rng.uniform(0.001, 0.05, (n, n))
    strong = rng.random((n, n)) < 2 / n
    p[strong] = rng.uniform(0.5, 0.95, int(strong.sum()))
    np.fill_diagonal(p, 0.0)
    sampling.sampled_marginals(p, samples=16, seed=0)  # load the compiled kernels
    for moves in moves_list:
        sampling.WIDE_MOVES = moves
        start = time.perf_counter()
        result = sampling.sampled_marginals(p, samples=2048, seed=1)
        seconds = time.perf_counter() - start
        _, covariance = result.errors_of(np.ones(n))
        print(
            f"pile of {n}, moves {moves:3d}: {seconds:.2f} s, largest R-hat "
            f"{result.convergence_of(np.ones(n)).max():.2f}, largest s.e. {np.sqrt(np.diag(covariance)).max():.4f}, "
            f"acceptance {result.acceptance:.3f}",
            flush=True,
        )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--link", type=float, default=1e-3)
    parser.add_argument("--moves", type=lambda text: [int(v) for v in text.split(",")], default=[150, 40, 16])
    parser.add_argument("--reference-samples", type=int, default=32768)
    parser.add_argument("--pile", type=int, default=0)
    args = parser.parse_args()
    if args.pile:
        pile(args.pile, args.moves)
        return
    p = weak_groups(30, 5, args.link, 0)
    n = len(p)
    sampling.sampled_marginals(p[:70, :70], samples=16, seed=0)  # load the compiled kernels
    start = time.perf_counter()
    reference = sampling.sampled_marginals(p, samples=args.reference_samples, seed=99)
    truth, covariance = reference.errors_of(np.ones(n))
    truth_errors = np.sqrt(np.diag(covariance))
    print(f"reference: {time.perf_counter() - start:.1f} s, largest s.e. {truth_errors.max():.4f}", flush=True)
    for moves in args.moves:
        sampling.WIDE_MOVES = moves
        for samples in (1024, 4096):
            start = time.perf_counter()
            result = sampling.sampled_marginals(p, samples=samples, seed=1)
            seconds = time.perf_counter() - start
            costs, covariance = result.errors_of(np.ones(n))
            deviation = np.abs(costs - truth)
            print(
                f"moves {moves:3d} samples {samples:5d}: {seconds:.2f} s, worst EC error {deviation.max():.4f}, "
                f"largest s.e. {np.sqrt(np.diag(covariance)).max():.4f}",
                flush=True,
            )


if __name__ == "__main__":
    main()
