"""Weakly linked groups: the sampler with and without block Gibbs against a reference.

Instances: ``groups`` dense groups of ``size`` boxes (inside a group every pair
``U(0.05, 0.95)``), every pair across groups ``link`` (1e-4 .. 1e-2). Reference:

* up to 8 boxes, the exact engine on the whole matrix;
* above, exact per group plus the first-order coupling correction (worlds with exactly
  one relation across, whose weight is exact given the groups; the error is of order
  ``link ** 2`` per pair of relations across) -- or, with ``--reference-samples``, a long
  run of the sampler (its own standard error is printed and enters the coverage).

For every instance and seed it prints the worst EC error, the largest standard error, the
share of ECs within 2 standard errors and the seconds of one ``sampled_marginals`` call
(``--samples`` recorded sweeps; the default is the library's default).

Usage::

    python benchmarks/weak_links.py --groups 8 --size 5 --links 1e-4,1e-3,1e-2 --seeds 10 \
        --json benchmarks/results/weak-links.json
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from unstack.atomic import atomic_write_text
from unstack.reasoner.marginals import exact_marginals
from unstack.reasoner.sampling import DEFAULT_SAMPLES, sampled_marginals
from unstack.reasoner.small import small_marginals


def weak_groups(groups: int, size: int, link: float, seed: int) -> np.ndarray:
    """Dense groups (``U(0.05, 0.95)`` inside), every pair across exactly ``link``."""
    rng = np.random.default_rng(seed)
    n = groups * size
    p = np.full((n, n), link)
    for g in range(groups):
        block = slice(g * size, (g + 1) * size)
        p[block, block] = rng.uniform(0.05, 0.95, (size, size))
    np.fill_diagonal(p, 0.0)
    return p


def _log_partition(p: np.ndarray) -> tuple[np.ndarray, float]:
    """Exact marginals and the true ``log Z`` of a small group (undoing the engine's scaling)."""
    marginals, _, scaled = small_marginals(p)
    off = ~np.eye(len(p), dtype=bool)
    with np.errstate(divide="ignore"):
        return marginals, scaled + float(np.log(np.maximum(p, 1.0 - p))[off].sum())


def first_order_reference(p: np.ndarray, size: int) -> np.ndarray:
    """Marginals: exact per group plus the worlds with exactly one relation across."""
    n = len(p)
    groups = [np.arange(start, start + size) for start in range(0, n, size)]
    group_of = np.repeat(np.arange(len(groups)), size)
    across = group_of[:, None] != group_of[None, :]
    odds = np.where(across, p / (1.0 - p), 0.0)
    base = np.zeros((n, n))
    lowest = np.zeros(n)  # P(x has no supporter in its group)
    highest = np.zeros(n)  # P(y supports no box of its group)
    given_lowest = np.zeros((n, size, size))
    given_highest = np.zeros((n, size, size))
    for block in groups:
        q = p[np.ix_(block, block)]
        marginals, log_z = _log_partition(q)
        base[np.ix_(block, block)] = marginals
        for a, x in enumerate(block):
            column = q.copy()
            column[:, a] = 0.0
            given_lowest[x], log_low = _log_partition(column)
            lowest[x] = np.exp(log_low - log_z + np.log1p(-np.delete(q[:, a], a)).sum())
            row = q.copy()
            row[a, :] = 0.0
            given_highest[x], log_high = _log_partition(row)
            highest[x] = np.exp(log_high - log_z + np.log1p(-np.delete(q[a, :], a)).sum())
    weight = odds * lowest[:, None] * highest[None, :]  # one relation x -> y across, relative weight
    total = weight.sum()
    result = weight.copy()
    for g, block in enumerate(groups):
        mine = group_of == g
        touching = weight[mine].sum() + weight[:, mine].sum()
        inner = base[np.ix_(block, block)] * (1.0 + total - touching)
        for x in block:
            inner += given_lowest[x] * weight[x, ~mine].sum()
            inner += given_highest[x] * weight[~mine, x].sum()
        result[np.ix_(block, block)] = inner
    result /= 1.0 + total
    np.fill_diagonal(result, 0.0)
    return result


def run(args: argparse.Namespace) -> list[dict[str, Any]]:
    rows = []
    for link in args.links:
        for seed in range(args.seeds):
            p = weak_groups(args.groups, args.size, link, seed)
            n = len(p)
            truth_errors = np.zeros(n)
            if n <= 8:
                truth = exact_marginals(p).marginals.sum(axis=1)
                reference = "exact"
            elif args.reference_samples:
                long = sampled_marginals(p, samples=args.reference_samples, seed=10_000 + seed)
                truth, covariance = long.errors_of(np.ones(n))
                truth_errors = np.sqrt(np.diag(covariance))
                reference = f"sampler {args.reference_samples} sweeps"
            else:
                truth = first_order_reference(p, args.size).sum(axis=1)
                reference = "first order"
            for blocks, samples in [(blocks, samples) for blocks in args.blocks for samples in args.samples]:
                start = time.perf_counter()
                result = sampled_marginals(p, samples=samples, seed=seed, blocks=blocks)
                seconds = time.perf_counter() - start
                costs, covariance = result.errors_of(np.ones(n))
                errors = np.sqrt(np.diag(covariance))
                deviation = np.abs(costs - truth)
                row = {
                    "groups": args.groups,
                    "size": args.size,
                    "link": link,
                    "seed": seed,
                    "blocks": blocks,
                    "reference": reference,
                    "max_ec_error": float(deviation.max()),
                    "max_standard_error": float(errors.max()),
                    "reference_max_standard_error": float(truth_errors.max()),
                    "covered": int(np.sum(deviation <= 2 * np.sqrt(errors**2 + truth_errors**2))),
                    "values": n,
                    "seconds": seconds,
                    "samples": result.samples,
                    "samples_requested": samples,
                    "acceptance": result.acceptance,
                }
                rows.append(row)
                print(
                    f"n={n} link={link:g} seed={seed} blocks={blocks!s:5s} samples={samples} "
                    f"max EC error {row['max_ec_error']:.4f} "
                    f"max s.e. {row['max_standard_error']:.4f} covered {row['covered']}/{n} {seconds:.2f} s "
                    f"({reference})",
                    flush=True,
                )
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--groups", type=int, default=8)
    parser.add_argument("--size", type=int, default=5)
    parser.add_argument("--links", type=lambda text: [float(v) for v in text.split(",")], default=[1e-3])
    parser.add_argument("--seeds", type=int, default=5)
    parser.add_argument(
        "--samples",
        type=lambda text: [None if v == "default" else int(v) for v in text.split(",")],
        default=[DEFAULT_SAMPLES],
        help="comma-separated sweep budgets; 'default': the library's default for the group's size",
    )
    parser.add_argument("--reference-samples", type=int, default=0)
    parser.add_argument(
        "--blocks", type=lambda text: [v == "on" for v in text.split(",")], default=[True, False], help="on,off"
    )
    parser.add_argument("--json", type=Path)
    args = parser.parse_args()
    sampled_marginals(weak_groups(2, 5, 1e-3, 0), samples=64, seed=0)  # load the compiled kernels
    rows = run(args)
    for blocks, samples, link in [(b, s, link) for b in args.blocks for s in args.samples for link in args.links]:
        chosen = [r for r in rows if r["blocks"] == blocks and r["link"] == link and r["samples_requested"] == samples]
        covered = sum(r["covered"] for r in chosen) / sum(r["values"] for r in chosen)
        worst = sorted(r["max_ec_error"] for r in chosen)
        print(
            f"blocks={blocks!s:5s} samples={samples} link={link:g}: worst EC error median "
            f"{worst[len(worst) // 2]:.4f} worst {worst[-1]:.4f}, within 2 s.e. {100 * covered:.1f} %, "
            f"seconds {min(r['seconds'] for r in chosen):.2f}-{max(r['seconds'] for r in chosen):.2f}"
        )
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(f"peak RSS {peak:.0f} MiB; load average before/after {os.getloadavg()}")
    if args.json:
        atomic_write_text(args.json, json.dumps({"argv": sys.argv, "peak_rss_mib": peak, "rows": rows}, indent=1))


if __name__ == "__main__":
    main()
