"""How many sweeps a classifier pile needs: the spread and the memory of each box's EC.

The error of a sampled EC after ``N`` recorded sweeps is about ``sd * sqrt(tau / N)``, where
``sd`` is the spread of the box's EC from one sweep to the next (the number of boxes it
supports in the chain's current world) and ``tau`` the integrated autocorrelation time in
sweeps. Both belong to the pile's distribution and the sampler's moves, not to the machine,
so they say how far a time budget is from an error target before any timing. For every pile
of a data set (every box detected, the default model's probabilities) this prints the box
with the largest ``sd**2 * tau`` and the sweeps it needs for a standard error of 0.01 (an
error within 0.02 at about 2 standard errors), from the raw indicators of two chains of
:func:`unstack.reasoner.sampling.sample_worlds`.

Usage::

    unstack simulate --configs 8 --seed 7 --jobs 2 --out scenes40
    python benchmarks/intrinsic_variance.py scenes40 --worlds 3000
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
from script_arguments import data_sets_parser, pile_probabilities

from unstack.reasoner.sampling import sample_worlds


def autocorrelation_time(series: np.ndarray) -> float:
    """Integrated autocorrelation time (sweeps), summed until the correlation falls below 0.05."""
    centred = series - series.mean()
    variance = float(np.dot(centred, centred)) / len(centred)
    if variance == 0.0:
        return 1.0
    total = 1.0
    for lag in range(1, len(centred) // 4):
        correlation = float(np.dot(centred[:-lag], centred[lag:])) / len(centred) / variance
        if correlation < 0.05:
            break
        total += 2.0 * correlation
    return total


def main(argv: list[str]) -> int:
    parser = data_sets_parser(__doc__.split("\n\n")[0], piles=None, several=False)
    parser.add_argument("--worlds", type=int, default=3000, help="sweeps per chain")
    parser.add_argument("--chains", type=int, default=2)
    args = parser.parse_args(argv)
    for path, scene, probabilities in pile_probabilities(Path(args.data), args.piles):
        draws = [sample_worlds(probabilities, args.worlds, seed=seed) for seed in range(args.chains)]
        rows = []
        for box in range(len(probabilities)):
            spreads = [float(chain[:, box].sum(axis=1).std()) for chain in draws]
            memories = [autocorrelation_time(chain[:, box].sum(axis=1).astype(float)) for chain in draws]
            spread, memory = float(np.mean(spreads)), float(np.mean(memories))
            rows.append((spread**2 * memory, box, spread, memory))
        rows.sort(reverse=True)
        _, box, spread, memory = rows[0]
        print(
            f"{path.stem}: {len(probabilities)} boxes; worst box {scene.box_ids[box]}: sd {spread:.2f} per sweep, "
            f"tau {memory:.1f} sweeps -> {spread**2 * memory / 0.01**2:,.0f} sweeps for a standard error of 0.01",
            flush=True,
        )
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
