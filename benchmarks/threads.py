"""The exact engine with 1 and 2 numba threads, n = 6..8, one seeded dense instance per size.

Usage: ``python benchmarks/threads.py`` (best of 3 after a warm-up; n = 8 runs once).
"""

from __future__ import annotations

import time

import numba
import numpy as np

from unstack.reasoner.marginals import exact_marginals


def dense(n: int, rng: np.random.Generator) -> np.ndarray:
    probabilities = rng.uniform(0.05, 0.95, (n, n))
    np.fill_diagonal(probabilities, 0.0)
    return probabilities


def main() -> None:
    rng = np.random.default_rng(0)
    exact_marginals(dense(3, rng))  # compile or load the cached engine
    for n in (6, 7, 8):
        probabilities = dense(n, rng)
        for threads in (1, 2):
            numba.set_num_threads(threads)
            times = []
            for _ in range(3 if n < 8 else 1):
                start = time.perf_counter()
                exact_marginals(probabilities)
                times.append(time.perf_counter() - start)
            print(f"n = {n}, {threads} thread(s): {min(times):.4f} s")


if __name__ == "__main__":
    main()
