"""Simulator benchmark: CPU seconds per configuration and configurations per minute.

Runs ``simulate_dataset`` on the paper's setting (30-40 boxes of the two paper sizes in a
2 m section) with 1 worker and with 2 workers into fresh folders, reads the CPU seconds
of each phase from ``timings.jsonl``, and prints a table with the reference measured on
this machine kind (6.7 s generation + 9.2 s ground truth + 0.3 s scan per configuration
on one core) and the speed-up of 2 workers over 1.

Usage::

    python benchmarks/simulation.py --configs 6 --seed 0 --json simulation-benchmark.json
"""

from __future__ import annotations

import argparse
import json
import statistics
import tempfile
import time
from pathlib import Path

from rich.console import Console

from unstack.atomic import atomic_write_text
from unstack.cli.text import number_table
from unstack.sim.dataset import simulate_dataset
from unstack.sim.settings import SimulationSettings

REFERENCE = {"generation": 6.7, "ground_truth": 9.2, "scan": 0.3}


def run(configs: int, seed: int, jobs: int, boxes: tuple[int, int]) -> dict[str, object]:
    """One data set in a temporary folder: wall time and per-phase CPU seconds."""
    with tempfile.TemporaryDirectory() as folder:
        start = time.perf_counter()
        simulate_dataset(folder, SimulationSettings(boxes=boxes), configs=configs, seed=seed, jobs=jobs)
        wall = time.perf_counter() - start
        timings = [json.loads(line) for line in (Path(folder) / "timings.jsonl").read_text().splitlines()]
    phases = {phase: statistics.mean(t[phase] for t in timings) for phase in REFERENCE}
    return {"jobs": jobs, "configs": configs, "wall_seconds": wall, "per_minute": 60.0 * configs / wall, **phases}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--configs", type=int, default=6)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--boxes", default="30-40")
    parser.add_argument("--json", type=Path, default=None)
    arguments = parser.parse_args()
    low, high = (int(part) for part in arguments.boxes.split("-"))
    results = [run(arguments.configs, arguments.seed, jobs, (low, high)) for jobs in (1, 2)]
    measured = [
        (str(result["jobs"]), *(f"{result[phase]:.2f}" for phase in (*REFERENCE, "per_minute")),
         f"{result['wall_seconds']:.1f}")
        for result in results
    ]  # fmt: skip
    table = number_table(
        f"simulator, {low}-{high} boxes, {arguments.configs} configurations, seed {arguments.seed}",
        ("workers", "generation CPU s", "ground truth CPU s", "scan CPU s", "configs / min", "wall s"),
        [*measured, ("reference", *(f"{REFERENCE[phase]:.2f}" for phase in REFERENCE), "", "")],
    )
    console = Console()
    console.print(table)
    speedup = float(results[1]["per_minute"]) / float(results[0]["per_minute"])  # type: ignore[arg-type]
    console.print(f"2 workers / 1 worker: {speedup:.2f}x (target >= 1.8x on a quiet machine)")
    if arguments.json:
        atomic_write_text(
            arguments.json, json.dumps({"results": results, "speedup": speedup, "reference": REFERENCE}, indent=2)
        )


if __name__ == "__main__":
    main()
