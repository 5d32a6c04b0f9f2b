"""How many piles issue 34's target needs: the power of a paired test of "half the gap closed".

The target asks a policy to move fewer boxes than highest first by two standard errors of the
paired difference on 30 piles per family, and to close half of the gap to the physics look-ahead.
For each family this reads three container runs on the same piles (highest first, the
look-ahead, and a policy) and prints:

* the gap: highest first's boxes moved per pile minus the look-ahead's;
* the policy's paired difference from highest first and the spread of that difference pile by
  pile (its standard deviation, which sets the standard error: sd / sqrt(piles));
* for a policy whose mean lead is exactly half the gap and whose pile-by-pile spread is the
  measured one: the expected number of standard errors at the piles run, the chance that such
  a policy is seen two standard errors ahead (normal approximation), and the piles needed for
  an expected two standard errors and for that chance to be 80 %.

Usage::

    python benchmarks/target_power.py --policy hybrid_faces_free \\
        four=veto-f30-four,la-f30-four,hf-f30-four stacked=veto-f30-stacked,la-f30-stacked,hf-f30-stacked

Each family is ``NAME=HIGHEST_RUN,LOOKAHEAD_RUN,POLICY_RUN`` (folders of ``unstack experiment
container``; the makers ``highest``, ``lookahead`` and ``--policy`` are read from them).
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from paired_piles import boxes_moved

#: The standard errors the target asks for.
TARGET_Z = 2.0
#: The chance of seeing the target that "enough piles" means.
POWER = 0.8


def normal_cdf(x: float) -> float:
    """The standard normal distribution function."""
    return 0.5 * (1.0 + math.erf(x / math.sqrt(2.0)))


def paired(base: Path, base_maker: str, run: Path, maker: str) -> tuple[np.ndarray, np.ndarray]:
    """Boxes moved per pile of two makers on the piles both runs hold (the same scene, the same detector)."""
    first, second = boxes_moved(base, base_maker), boxes_moved(run, maker)
    piles = sorted(pile for pile in set(first) & set(second) if first[pile][0] == second[pile][0])
    return (
        np.array([first[pile][1] for pile in piles], dtype=float),
        np.array([second[pile][1] for pile in piles], dtype=float),
    )


def family_power(highest_run: Path, lookahead_run: Path, policy_run: Path, policy: str) -> dict[str, float]:
    """The figures of one family (see the module)."""
    highest, lookahead = paired(highest_run, "highest", lookahead_run, "lookahead")
    base, moved = paired(highest_run, "highest", policy_run, policy)
    difference = moved - base
    piles = len(difference)
    spread = float(difference.std(ddof=1))
    half_gap = float(highest.mean() - lookahead.mean()) / 2.0
    expected_z = half_gap * math.sqrt(piles) / spread
    z_power = 0.8416212335729143  # the normal quantile of POWER
    return {
        "piles": piles,
        "gap": 2.0 * half_gap,
        "difference": float(difference.mean()),
        "standard_error": spread / math.sqrt(piles),
        "spread": spread,
        "expected_z": expected_z,
        "chance": normal_cdf(expected_z - TARGET_Z),
        "piles_for_z": (TARGET_Z * spread / half_gap) ** 2,
        "piles_for_power": ((TARGET_Z + z_power) * spread / half_gap) ** 2,
    }


def table_row(name: str, row: dict[str, float]) -> str:
    """One family's printed row (see the header :func:`main` prints)."""
    return (
        f"{name} | {row['piles']} | {row['gap']:.2f} | {row['difference']:+.2f} +- {row['standard_error']:.2f} "
        f"(sd {row['spread']:.2f}) | {row['expected_z']:.1f}, {row['chance']:.0%} | "
        f"{math.ceil(row['piles_for_z'])} / {math.ceil(row['piles_for_power'])}"
    )


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("families", nargs="+", help="NAME=HIGHEST_RUN,LOOKAHEAD_RUN,POLICY_RUN")
    parser.add_argument("--policy", required=True, help="the maker read from POLICY_RUN")
    arguments = parser.parse_args(argv)
    print(
        "family | piles | gap to the look-ahead | policy - highest first (sd per pile) | half the gap at these piles: "
        "expected s.e., chance of 2 s.e. | piles for 2 s.e. expected / seen with 80 %"
    )
    for item in arguments.families:
        name, _, folders = item.partition("=")
        runs = [Path(folder) for folder in folders.split(",")]
        if len(runs) != 3:
            print(
                f"target_power.py: error: {item}: expected NAME=HIGHEST_RUN,LOOKAHEAD_RUN,POLICY_RUN", file=sys.stderr
            )
            return 2
        print(table_row(name, family_power(runs[0], runs[1], runs[2], arguments.policy)), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
