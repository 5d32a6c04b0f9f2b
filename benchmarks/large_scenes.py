"""Validation and accuracy of the sampling engine (``--method approx``) for large scenes.

Three parts, one run, every figure printed with the command line that made it:

``exact``
    every ``dense`` and ``sparse`` instance of :mod:`instances` for n = 3..8 and the given
    seeds: ``decide(method="approx")`` within the time limit against the exact engine --
    worst EC error, whether the choice is the same, the regret (true EC of the sampled
    choice minus the true minimum), and the coverage of the error bars (share of exact ECs
    and marginals within 2 standard errors; about 95 % is right).
``blocks``
    n = 10..40 boxes in independent groups of 5 (pile-like probabilities inside a group,
    exactly 0 across): the sampler runs on the whole matrix, without the factorisation,
    and is compared with the exact engine group by group.
``scenes``
    support matrices that the shipped classifier gives for simulated piles (every box of
    each configuration of a data set made by ``unstack simulate``): one long run is the
    reference (its own standard error is printed), then several seeded runs within the time
    limit are compared with it; peak memory of the process.

Usage::

    python benchmarks/large_scenes.py --time-limit 1 --seeds 3 --scenes DATASET --json out.json

where ``DATASET`` comes from ``unstack simulate --configs 8 --seed 7 --jobs 2 --out DATASET``.
"""

from __future__ import annotations

import argparse
import json
import resource
import sys
import time
from collections.abc import Iterator
from contextlib import contextmanager
from functools import partial
from itertools import product
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from instances import instance

from unstack.atomic import atomic_write_text
from unstack.reasoner.decision import decide
from unstack.reasoner.marginals import exact_marginals
from unstack.reasoner.sampling import sampled_marginals
from unstack.supports import Supports


def ids(n: int) -> list[str]:
    return [f"b{i:02d}" for i in range(n)]


def scores(
    costs: np.ndarray, errors: np.ndarray, truth: np.ndarray, truth_errors: np.ndarray | None = None
) -> dict[str, Any]:
    """Worst EC error, coverage of 2 standard errors, choice agreement and regret."""
    spread = errors if truth_errors is None else np.sqrt(errors**2 + truth_errors**2)
    deviation = np.abs(costs - truth)
    chosen = int(np.argmin(costs))
    return {
        "max_ec_error": float(deviation.max()),
        "max_standard_error": float(errors.max()),
        "covered": int(np.sum(deviation <= 2 * spread)),
        "values": len(costs),
        "same_choice": bool(np.isclose(truth[chosen], truth.min(), rtol=0, atol=1e-12)),
        "regret": float(truth[chosen] - truth.min()),
    }


def part_exact(sizes: list[int], seeds: int, time_limit: float) -> list[dict[str, Any]]:
    rows = []
    for family in ("dense", "sparse"):
        for n in sizes:
            for seed in range(seeds):
                p = instance(family, n, seed)
                truth = exact_marginals(p).marginals
                decision = decide(Supports(ids(n), p), method="approx", time_limit=time_limit, seed=seed)
                assert decision.expected_cost_errors is not None and decision.marginal_errors is not None
                row = scores(decision.expected_costs, decision.expected_cost_errors, truth.sum(axis=1))
                off = ~np.eye(n, dtype=bool)
                deviation = np.abs(decision.marginals - truth)[off]
                row |= {
                    "part": "exact",
                    "family": family,
                    "n": n,
                    "seed": seed,
                    "max_marginal_error": float(deviation.max()),
                    "marginals_covered": int(np.sum(deviation <= 2 * decision.marginal_errors[off])),
                    "marginals": int(off.sum()),
                    "seconds": decision.seconds,
                }
                rows.append(row)
                print(summary(row), flush=True)
    return rows


def block_matrix(n: int, size: int, rng: np.random.Generator) -> np.ndarray:
    """Pile-like groups of ``size`` boxes, nothing across groups."""
    p = np.zeros((n, n))
    for start in range(0, n, size):
        block = slice(start, min(start + size, n))
        m = block.stop - block.start
        inner = rng.uniform(0.01, 0.08, (m, m))
        strong = rng.random((m, m)) < 0.3
        inner[strong] = rng.uniform(0.5, 0.95, int(strong.sum()))
        np.fill_diagonal(inner, 0.0)
        p[block, block] = inner
    return p


def part_blocks(sizes: list[int], seeds: int, time_limit: float) -> list[dict[str, Any]]:
    rows = []
    for n in sizes:
        for seed in range(seeds):
            p = block_matrix(n, 5, np.random.default_rng(seed))
            truth = np.zeros((n, n))
            for start in range(0, n, 5):
                block = slice(start, min(start + 5, n))
                truth[block, block] = exact_marginals(p[block, block]).marginals
            result = sampled_marginals(p, time_limit=time_limit, seed=seed)
            costs, covariance = result.errors_of(np.ones(n))
            row = scores(costs, np.sqrt(np.diag(covariance)), truth.sum(axis=1))
            row |= {
                "part": "blocks",
                "family": "groups of 5",
                "n": n,
                "seed": seed,
                "seconds": result.seconds,
                "samples": result.samples,
            }
            rows.append(row)
            print(summary(row), flush=True)
    return rows


def scene_matrices(dataset: Path) -> dict[str, np.ndarray]:
    """The shipped model's support probabilities for every box of every configuration."""
    from script_arguments import pile_probabilities

    return {path.stem: probabilities for path, _, probabilities in pile_probabilities(dataset)}


@contextmanager
def sampler_options(options: dict[str, bool]) -> Iterator[None]:
    """Run the decisions inside with these options of the sampler (``revisits``; ``decide`` does
    not take them, so the benchmark sets them on the function the decision calls)."""
    from unstack.reasoner import sampling

    plain = sampling._sampled_marginals
    sampling._sampled_marginals = partial(plain, **options)  # type: ignore[assignment]
    try:
        yield
    finally:
        sampling._sampled_marginals = plain  # type: ignore[assignment]


def part_scenes(
    dataset: Path,
    seeds: int,
    time_limit: float,
    reference_seconds: float,
    limit: int,
    settings: tuple[dict[str, bool], ...] = ({},),
) -> list[dict[str, Any]]:
    rows = []
    for name, p in list(scene_matrices(dataset).items())[:limit]:
        n = len(p)
        reference = sampled_marginals(p, time_limit=reference_seconds, seed=10_000)
        truth, truth_covariance = reference.errors_of(np.ones(n))
        truth_errors = np.sqrt(np.diag(truth_covariance))
        for seed, options in product(range(seeds), settings):
            with sampler_options(options):
                decision = decide(Supports(ids(n), p), method="approx", time_limit=time_limit, seed=seed)
            assert decision.expected_cost_errors is not None
            row = scores(decision.expected_costs, decision.expected_cost_errors, truth, truth_errors)
            row |= {
                "part": "scenes" + "".join(f", {key}={value}" for key, value in options.items()),
                "family": name,
                "n": n,
                "seed": seed,
                "seconds": decision.seconds,
                "choice_probability": decision.choice_probability,
                "samples": int(sum(decision.sampling["samples"])) if decision.sampling else 0,
                "reference_samples": reference.samples,
                "reference_max_standard_error": float(truth_errors.max()),
                "peak_rss_mib": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,
            }
            rows.append(row)
            print(summary(row), flush=True)
    return rows


def summary(row: dict[str, Any]) -> str:
    extra = ""
    if "choice_probability" in row:
        extra = (
            f"  P(min) {row['choice_probability']:.3f}  {row['samples']:,} sweeps"
            f"  reference s.e. {row['reference_max_standard_error']:.4f}"
        )
    return (
        f"{row['part']:6s} {row['family']:12s} n={row['n']:2d} seed={row['seed']}  "
        f"max EC error {row['max_ec_error']:.4f}  max s.e. {row['max_standard_error']:.4f}  "
        f"covered {row['covered']}/{row['values']}  same choice {row['same_choice']}  "
        f"regret {row['regret']:.4f}  {row['seconds']:.2f} s{extra}"
    )


def totals(rows: list[dict[str, Any]]) -> list[str]:
    lines = []
    parts = ["exact", "blocks", *sorted({row["part"] for row in rows if row["part"].startswith("scenes")})]
    for part in parts:
        chosen = [row for row in rows if row["part"] == part]
        if not chosen:
            continue
        covered = sum(row["covered"] for row in chosen) / sum(row["values"] for row in chosen)
        line = (
            f"{part}: {len(chosen)} runs, worst EC error {max(r['max_ec_error'] for r in chosen):.4f}, "
            f"median worst EC error {np.median([r['max_ec_error'] for r in chosen]):.4f}, "
            f"EC coverage of 2 s.e. {covered:.3f}, same choice {sum(r['same_choice'] for r in chosen)}/{len(chosen)}, "
            f"worst regret {max(r['regret'] for r in chosen):.4f}, slowest {max(r['seconds'] for r in chosen):.2f} s"
        )
        if part == "exact":
            marginal_cover = sum(r["marginals_covered"] for r in chosen) / sum(r["marginals"] for r in chosen)
            line += f", marginal coverage {marginal_cover:.3f}"
        if part.startswith("scenes"):
            line += f", within 0.02 {sum(r['max_ec_error'] <= 0.02 for r in chosen)}/{len(chosen)}"
            line += f", sweeps {min(r['samples'] for r in chosen):,}-{max(r['samples'] for r in chosen):,}"
            line += f", peak RSS {max(r['peak_rss_mib'] for r in chosen):.0f} MiB"
        lines.append(line)
    return lines


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--time-limit", type=float, default=1.0, help="seconds of sampling per decision")
    parser.add_argument("--seeds", type=int, default=3, help="seeds per instance")
    parser.add_argument("--max-exact", type=int, default=8, help="largest n compared with the exact engine")
    parser.add_argument("--scenes", type=Path, default=None, help="a data set made by unstack simulate")
    parser.add_argument("--scene-limit", type=int, default=8, help="configurations used from --scenes")
    parser.add_argument("--reference-seconds", type=float, default=60.0, help="length of the reference run")
    parser.add_argument("--parts", default="exact,blocks,scenes")
    parser.add_argument(
        "--compare",
        choices=("revisits",),
        default=None,
        help="in the scenes part, run each seed with this option of the sampler off and on",
    )
    parser.add_argument("--json", type=Path, default=None)
    args = parser.parse_args(argv)
    settings: tuple[dict[str, bool], ...] = (
        ({},) if args.compare is None else ({args.compare: False}, {args.compare: True})
    )
    parts = args.parts.split(",")
    start = time.perf_counter()
    rows: list[dict[str, Any]] = []
    if "exact" in parts:
        rows += part_exact(list(range(3, args.max_exact + 1)), args.seeds, args.time_limit)
    if "blocks" in parts:
        rows += part_blocks([10, 20, 30, 40], args.seeds, args.time_limit)
    if "scenes" in parts and args.scenes is not None:
        rows += part_scenes(
            args.scenes, args.seeds, args.time_limit, args.reference_seconds, args.scene_limit, settings
        )
    print(f"\ncommand: python benchmarks/large_scenes.py {' '.join(argv if argv is not None else sys.argv[1:])}")
    for line in totals(rows):
        print(line)
    print(f"total {time.perf_counter() - start:.0f} s")
    if args.json is not None:
        atomic_write_text(args.json, json.dumps({"argv": sys.argv[1:], "rows": rows, "totals": totals(rows)}, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
