"""A plan and a scene decision on a quiet machine and beside other work (a planner's:
:mod:`neighbours`), for this checkout and, side by side in the same run, an older one.

Each measurement runs in a fresh process whose ``unstack`` comes from the checkout named
(``PYTHONPATH``); the checkouts alternate, ``--rounds`` times each. Other work beside it:
``--busy``, loads of :mod:`neighbours` (0 is a quiet machine). Reported: the median
seconds of ``--repeat`` in-process calls (the first call, which loads the compiled kernels,
excluded), and the ratio baseline / this checkout.

Usage::

    git worktree add /tmp/baseline <older commit>
    python benchmarks/busy_core.py --baseline /tmp/baseline --rounds 2 --repeat 5 --busy 0,1,2,omp
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
from pathlib import Path

REPOSITORY = Path(__file__).resolve().parent.parent

_CHILD = r"""
import json, statistics, sys, time
import unstack
sys.path.insert(0, sys.argv[5])
import neighbours

supports = unstack.load_supports(sys.argv[1])
scene = unstack.load_scene(sys.argv[2])
repeat = int(sys.argv[3])
jobs = {
    "plan pile31.supports.json": lambda: unstack.plan(supports, seed=3),
    "decide pile5.scene.json": lambda: unstack.decide(scene, seed=3),
}
for job in jobs.values():
    job()
result = {}
for busy in sys.argv[4].split(","):
    running = neighbours.start(busy)
    try:
        for name, job in jobs.items():
            seconds = []
            for _ in range(repeat):
                start = time.perf_counter()
                job()
                seconds.append(time.perf_counter() - start)
            result[f"{name}, beside {busy}"] = statistics.median(seconds)
    finally:
        neighbours.stop(*running)
print(json.dumps(result))
"""


def measure(checkout: Path, repeat: int, busy: list[str]) -> dict[str, float]:
    """One child process on ``checkout``'s ``unstack``."""
    environment = {**os.environ, "PYTHONPATH": str(checkout)}
    examples = REPOSITORY / "examples"
    command = [
        sys.executable,
        "-c",
        _CHILD,
        str(examples / "pile31.supports.json"),
        str(examples / "pile5.scene.json"),
        str(repeat),
        ",".join(busy),
        str(Path(__file__).resolve().parent),
    ]
    output = subprocess.run(command, env=environment, capture_output=True, text=True, check=True, cwd="/")
    measured: dict[str, float] = json.loads(output.stdout.strip().splitlines()[-1])
    return measured


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--baseline", type=Path, required=True, help="an older checkout of the repository")
    parser.add_argument("--rounds", type=int, default=2)
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument(
        "--busy",
        type=lambda text: text.split(","),
        default=["0", "1", "2", "omp"],
        help="comma-separated loads beside it (benchmarks/neighbours.py)",
    )
    args = parser.parse_args(argv)
    print(
        f"python benchmarks/busy_core.py --baseline {args.baseline} --rounds {args.rounds} --repeat {args.repeat} "
        f"--busy {','.join(args.busy)}"
    )
    print(f"load average before: {os.getloadavg()[0]:.2f}")
    runs: dict[str, list[dict[str, float]]] = {"baseline": [], "this checkout": []}
    for _ in range(args.rounds):
        runs["baseline"].append(measure(args.baseline, args.repeat, args.busy))
        runs["this checkout"].append(measure(REPOSITORY, args.repeat, args.busy))
    print("| job, load beside it | baseline: median s per round | this checkout | baseline / this |")
    print("|---|---:|---:|---:|")
    for key in runs["baseline"][0]:
        old = [run[key] for run in runs["baseline"]]
        new = [run[key] for run in runs["this checkout"]]
        ratio = statistics.median(old) / statistics.median(new)
        print(
            f"| {key} | {' / '.join(f'{v:.2f}' for v in old)} | {' / '.join(f'{v:.2f}' for v in new)} | {ratio:.2f} |"
        )
    print(f"load average after: {os.getloadavg()[0]:.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
