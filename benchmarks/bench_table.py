"""Markdown table of a pytest-benchmark JSON file written by ``test_reasoner.py``.

One row per (family, n): exact and sat (median and min of the rounds) and sat / exact of
the medians -- both measured in the same run.

Usage::

    pytest benchmarks --benchmark-enable --benchmark-json bench.json
    python benchmarks/bench_table.py bench.json
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import Any


def seconds_text(value: float | None) -> str:
    if value is None:
        return ""
    if value < 0.01:
        return f"{value * 1000:.2f} ms"
    if value < 1:
        return f"{value * 1000:.1f} ms"
    return f"{value:.2f} s"


def table(report: dict[str, Any]) -> str:
    stats: dict[tuple[str, int, str], dict[str, float]] = {}
    for bench in report["benchmarks"]:
        info = bench["extra_info"]
        stats[info["family"], int(info["n"]), info["method"]] = bench["stats"]
    lines = [
        "| family | n | exact median | exact min | exact rounds | sat median | sat min | sat rounds | sat / exact |",
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for family, n in sorted({(f, n) for f, n, _ in stats}):
        exact = stats.get((family, n, "exact"))
        sat = stats.get((family, n, "sat"))
        cells = [family, str(n)]
        for method in (exact, sat):
            if method is None:
                cells += ["", "", ""]
            else:
                cells += [seconds_text(method["median"]), seconds_text(method["min"]), str(method["rounds"])]
        ratio = f"{sat['median'] / exact['median']:.3g}x" if exact and sat else ""
        lines.append("| " + " | ".join([*cells, ratio]) + " |")
    return "\n".join(lines) + "\n"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description="Markdown table of a pytest-benchmark JSON file.")
    parser.add_argument("json", type=Path)
    args = parser.parse_args(argv)
    sys.stdout.write(table(json.loads(args.json.read_text())))
    return 0


if __name__ == "__main__":
    sys.exit(main())
