"""Hundreds of boxes: ``unstack decide FILE`` end to end on weakly linked scenes of 64+ boxes.

Writes a supports file of ``groups`` dense groups of ``size`` boxes (inside a group every pair
``U(0.05, 0.95)``, every pair across ``link``; :func:`weak_links.weak_groups`), runs
``unstack decide FILE --json --seed S`` in a subprocess (``S`` = 3, 4, ... for ``--runs``
runs) and records its wall time and peak resident memory (``os.wait4``). With
``--reference-samples`` it also decides in-process with that many sweeps (seed 99, once per
scene) and reports the worst EC error of each answer against it, how many ECs lie within 2
combined standard errors, and the root mean square of the errors in combined standard
errors (about 1 when the error bars are honest).

Usage::

    python benchmarks/hundreds.py --boxes 150,256 --links 1e-3 --json benchmarks/results/hundreds.json
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from weak_links import weak_groups

from unstack.atomic import atomic_write_text
from unstack.reasoner.decision import decide
from unstack.supports import Supports


def run_command(path: Path, extra: list[str], seed: int = 3) -> tuple[dict[str, Any], float, float]:
    """``unstack decide`` on ``path``: its JSON, wall seconds and peak RSS in MiB."""
    start = time.perf_counter()
    process = subprocess.Popen(
        ["unstack", "decide", str(path), "--json", "--seed", str(seed), *extra],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    stdout = process.stdout.read() if process.stdout else ""
    _, status, usage = os.wait4(process.pid, 0)
    seconds = time.perf_counter() - start
    if status != 0:
        raise RuntimeError(process.stderr.read() if process.stderr else f"exit status {status}")
    return json.loads(stdout), seconds, usage.ru_maxrss / 1024


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--boxes", type=lambda text: [int(v) for v in text.split(",")], default=[150, 256])
    parser.add_argument("--size", type=int, default=5)
    parser.add_argument("--links", type=lambda text: [float(v) for v in text.split(",")], default=[1e-3])
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--reference-samples", type=int, default=0)
    parser.add_argument("--runs", type=int, default=1, help="runs of the command per scene (seeds 3, 4, ...)")
    parser.add_argument("--extra", default="", help="more options for unstack decide, e.g. '--time-limit 3'")
    parser.add_argument("--json", type=Path)
    args = parser.parse_args()
    rows = []
    with tempfile.TemporaryDirectory() as folder:
        for boxes in args.boxes:
            for link in args.links:
                p = weak_groups(-(-boxes // args.size), args.size, link, args.seed)[:boxes, :boxes]
                supports = Supports([f"b{i:03d}" for i in range(boxes)], p)
                path = Path(folder) / f"weak{boxes}.supports.json"
                supports.save(path)
                reference = (
                    decide(supports, samples=args.reference_samples, seed=99) if args.reference_samples else None
                )
                for run in range(args.runs):
                    answer, seconds, rss = run_command(path, args.extra.split(), seed=3 + run)
                    costs = np.array(answer["expected_costs"])
                    errors = np.array(answer["expected_cost_errors"])
                    row: dict[str, Any] = {
                        "boxes": boxes,
                        "link": link,
                        "seed": 3 + run,
                        "seconds": seconds,
                        "peak_rss_mib": rss,
                        "samples": answer["sampling"]["samples"],
                        "max_standard_error": float(errors.max()),
                        "choice": answer["choice"],
                    }
                    if reference is not None:
                        assert reference.expected_cost_errors is not None
                        deviation = np.abs(costs - reference.expected_costs)
                        combined = np.sqrt(errors**2 + reference.expected_cost_errors**2)
                        row |= {
                            "max_ec_error": float(deviation.max()),
                            "covered": int(np.sum(deviation <= 2 * combined)),
                            "rms_z": float(np.sqrt(np.mean((deviation / combined) ** 2))),
                            "reference_max_standard_error": float(reference.expected_cost_errors.max()),
                        }
                    rows.append(row)
                    print(json.dumps(row), flush=True)
    print(f"load average after {os.getloadavg()}")
    if args.json:
        atomic_write_text(args.json, json.dumps({"argv": sys.argv, "rows": rows}, indent=1))


if __name__ == "__main__":
    main()
