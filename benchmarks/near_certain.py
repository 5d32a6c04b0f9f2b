"""How honest the sampler's errors are where probabilities come within 1e-3 of 0 or 1.

For random 6-box matrices of four kinds -- ``near`` (30 % of the pairs within 1e-3 to 1e-12 of
0, 30 % as near 1), ``beta`` (Beta(0.3, 0.3): most near 0 or 1), ``uniform`` and ``low`` (only
the 30 % near 0) -- the sampler
(``decide(..., method="approx")``) against the exact engine on the same matrix: how many
expected costs lie beyond 4 of their standard errors, and how many of those came with no
warning (R-hat or acceptance), counting only errors above :data:`MATTERS` boxes (rare worlds
of 1e-9 make errors of 1e-4 that are many of their tiny standard errors, and decide nothing).
Matrices the exact engine refuses (contradicting hard evidence) are drawn again.

Usage::

    python benchmarks/near_certain.py --instances 100 --seed 0
"""

from __future__ import annotations

import argparse

import numpy as np

import unstack
from unstack.errors import UnstackError

KINDS = ("near", "beta", "uniform", "low")
#: An error in an expected cost smaller than this (boxes) is not counted.
MATTERS = 0.01


def matrix(kind: str, n: int, rng: np.random.Generator) -> np.ndarray:
    """A random ``n`` x ``n`` support-probability matrix of ``kind`` (see the module)."""
    p = rng.beta(0.3, 0.3, (n, n)) if kind == "beta" else rng.uniform(0.0, 1.0, (n, n))
    if kind in ("near", "low"):
        draw = rng.uniform(size=(n, n))
        small = 10.0 ** -rng.uniform(3, 12, (n, n))
        p[draw < 0.3] = small[draw < 0.3]
        if kind == "near":
            p[draw > 0.7] = 1.0 - small[draw > 0.7]
    np.fill_diagonal(p, 0.0)
    return p


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--instances", type=int, default=100, help="matrices per kind")
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    head = f"beyond 4 standard errors and {MATTERS} boxes"
    print(f"| kind | expected costs | {head} | of those, with no warning | largest error: all / no warning (boxes) |")
    print("|---|---:|---:|---:|---:|")
    for number, kind in enumerate(KINDS):
        rng = np.random.default_rng([args.seed, number])
        costs = beyond = silent = 0
        largest = largest_silent = 0.0
        done = 0
        while done < args.instances:
            supports = unstack.Supports([f"b{k}" for k in range(6)], matrix(kind, 6, rng))
            try:
                exact = unstack.decide(supports, method="exact", cost="count")
            except UnstackError:
                continue
            sampled = unstack.decide(supports, method="approx", cost="count", seed=done)
            error = np.abs(sampled.expected_costs - exact.expected_costs)
            off = (error > 4 * sampled.expected_cost_errors) & (error > MATTERS)
            costs += len(error)
            beyond += int(off.sum())
            silent += int(off.sum()) if not sampled.warnings else 0
            largest = max(largest, float(error[off].max(initial=0.0)))
            if not sampled.warnings:
                largest_silent = max(largest_silent, float(error[off].max(initial=0.0)))
            done += 1
        print(f"| {kind} | {costs} | {beyond} | {silent} | {largest:.3f} / {largest_silent:.3f} |", flush=True)


if __name__ == "__main__":
    main()
