"""Table I: the number of consistent worlds for n boxes, against the paper and OEIS A000798.

Counted structurally by the exact engine (all probabilities 1/2, so every world counts)
and, up to ``sat_max`` boxes, by listing the worlds with the SAT solver.

Examples
--------
>>> rows = table1(sizes=(3, 4))
>>> [(row["n"], row["exact"], row["paper"]) for row in rows]
[(3, 29, 29), (4, 355, 355)]
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from typing import Any

import numpy as np

from unstack.parameters import Interval
from unstack.reasoner.consistency import PREORDER_COUNTS

__all__ = ["OEIS_A000798", "PAPER_TABLE_I", "TABLE_SIZE", "table1"]

#: The paper's Table I: consistent worlds q' for n = 3..6.
PAPER_TABLE_I = {3: 29, 4: 355, 5: 6942, 6: 209527}
#: OEIS A000798, the number of preorders (quasi-orders) on n labelled elements: a view of
#: :data:`unstack.reasoner.consistency.PREORDER_COUNTS`, the one table of these counts.
OEIS_A000798 = dict(enumerate(PREORDER_COUNTS))


#: The n a row of Table I may have: 8 boxes take minutes, 9 would take days.
TABLE_SIZE = Interval(int, 3, 8)


def table1(sizes: Sequence[int] = (3, 4, 5, 6, 7), *, sat_max: int = 5) -> list[dict[str, Any]]:
    """One row per n: all worlds 2^(n(n-1)), consistent worlds by each method, the references.

    Every n is checked against :data:`TABLE_SIZE` before any counting.
    """
    from unstack.reasoner.marginals import exact_marginals
    from unstack.reasoner.worlds import enumerate_worlds
    from unstack.supports import Supports

    sizes = [TABLE_SIZE.check(n, "n") for n in sizes]
    rows = []
    for n in sizes:
        half = np.full((n, n), 0.5)
        np.fill_diagonal(half, 0.0)
        start = time.perf_counter()
        exact = exact_marginals(half, max_boxes=max(n, 8)).consistent_worlds
        exact_seconds = time.perf_counter() - start
        row: dict[str, Any] = {
            "n": n,
            "all_worlds": 2 ** (n * (n - 1)),
            "exact": exact,
            "exact_seconds": round(exact_seconds, 4),
            "paper": PAPER_TABLE_I.get(n),
            "oeis": OEIS_A000798.get(n),
        }
        if n <= sat_max:
            start = time.perf_counter()
            row["sat"] = len(enumerate_worlds(Supports([f"b{k}" for k in range(n)], half), max_boxes=max(n, 6)))
            row["sat_seconds"] = round(time.perf_counter() - start, 4)
        rows.append(row)
    return rows
