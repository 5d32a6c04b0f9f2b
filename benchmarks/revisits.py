"""Re-inserting the noisiest boxes more often: the real spread of the ECs, with and without.

For each pile of a data set (every box detected, the default model's probabilities) this runs
the sampler ``--runs`` times with different seeds and a fixed number of sweeps, once with the
revisit schedule (:mod:`unstack.reasoner.revisits`, the default) and once with every box in
turn, and prints for each setting the spread of each box's EC *across the runs* (its real
error, whatever the error bars say) next to the standard error the runs reported: the
largest spread, the boxes with the six largest spreads, and the ratio of spread to reported
error (about 1 when the error bars are honest).

Usage::

    unstack simulate --configs 8 --seed 7 --jobs 2 --out scenes40
    python benchmarks/revisits.py scenes40 --piles 3 --runs 16 --samples 50000
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np
from script_arguments import data_sets_parser, pile_probabilities

from unstack.reasoner.sampling import sampled_marginals


def spread(p: np.ndarray, runs: int, samples: int, revisits: bool) -> tuple[np.ndarray, np.ndarray, float]:
    """Each box's EC spread across ``runs`` seeded runs, the root mean square of the reported
    standard errors, and the mean seconds per run."""
    n = len(p)
    costs, errors = [], []
    started = time.perf_counter()
    for seed in range(runs):
        result = sampled_marginals(p, samples=samples, seed=100 + seed, revisits=revisits)
        estimate, covariance = result.errors_of(np.ones(n))
        costs.append(estimate)
        errors.append(np.sqrt(np.diag(covariance)))
    seconds = (time.perf_counter() - started) / runs
    return np.array(costs).std(axis=0, ddof=1), np.sqrt((np.array(errors) ** 2).mean(axis=0)), seconds


def main(argv: list[str]) -> int:
    parser = data_sets_parser(__doc__.split("\n\n")[0], piles=3, several=False)
    parser.add_argument("--runs", type=int, default=16)
    parser.add_argument("--samples", type=int, default=50_000)
    args = parser.parse_args(argv)
    print(f"python benchmarks/revisits.py {args.data} --piles {args.piles} --runs {args.runs} --samples {args.samples}")
    for path, _, p in pile_probabilities(Path(args.data), args.piles):
        for revisits in (False, True):
            real, reported, seconds = spread(p, args.runs, args.samples, revisits)
            top = np.argsort(-real)[:6]
            ratio = real[reported > 1e-4] / reported[reported > 1e-4]
            print(
                f"{path.stem} ({len(p)} boxes) {'revisits' if revisits else 'in turn '}: largest spread "
                f"{real.max():.4f}; six largest {', '.join(f'{v:.4f}' for v in real[top])} (reported "
                f"{', '.join(f'{v:.4f}' for v in reported[top])}); spread / reported median {np.median(ratio):.2f}, "
                f"largest {ratio.max():.2f}; {seconds:.2f} s a run",
                flush=True,
            )
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
