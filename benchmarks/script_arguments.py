"""What the benchmark scripts over simulated data sets share: their arguments and table heads."""

from __future__ import annotations

import argparse


def data_sets_parser(description: str, *, piles: int, several: bool = True) -> argparse.ArgumentParser:
    """A parser of one data set folder (``several``: one or more) and ``--piles``."""
    parser = argparse.ArgumentParser(description=description)
    if several:
        parser.add_argument("data", nargs="+", help="data set folders of unstack simulate")
    else:
        parser.add_argument("data", help="a data set folder of unstack simulate")
    parser.add_argument("--piles", type=int, default=piles, help="the first N piles of each data set")
    return parser


def print_markdown_head(*columns: str, numbers_from: int | None = None) -> None:
    """Print a Markdown table's head; the columns from ``numbers_from`` on are right-aligned."""
    first = len(columns) if numbers_from is None else numbers_from
    print("| " + " | ".join(columns) + " |")
    print("|" + "|".join("---" if k < first else "---:" for k in range(len(columns))) + "|")
