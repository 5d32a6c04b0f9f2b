"""The reasoner's numbers on fixed inputs, kept to check that a refactoring changes none of them.

``python tests/reasoner/golden_numbers.py --write`` records them in ``golden_numbers.json``
beside this file (do it only when a change of numbers is intended, and say so in the commit);
``python tests/reasoner/golden_numbers.py`` compares the present code with the file byte for
byte and prints every difference; ``tests/reasoner/test_golden_numbers.py`` runs the same
comparison in the test suite, exactly for choices and orders and to 1e-12 for floats, without
the SHA-256 of the whole arrays (another CPU may compile the fast-math kernels to other
instructions). Whole sampled arrays are kept as row and column sums plus that digest.

The inputs cover both layouts of the sampler's kernels (one 64-bit word for up to 63 boxes, word
arrays above), the exact engine, a decision and a plan from the shipped examples and a scene decision
with the default model.
"""

from __future__ import annotations

import hashlib
import json
import sys
from pathlib import Path
from typing import Any

import numpy as np

GOLDEN_FILE = Path(__file__).with_name("golden_numbers.json")
EXAMPLES = Path(__file__).resolve().parents[2] / "examples"

#: (boxes, sweeps, seed) of the random support matrices given to the sampler.
SAMPLED_CASES = ((12, 1024, 1), (40, 512, 2), (70, 256, 3))


def _random_supports(boxes: int, seed: int) -> np.ndarray:
    """A support-probability matrix with a zero diagonal, drawn from ``seed``."""
    probabilities = np.random.default_rng(seed).uniform(0.0, 0.4, (boxes, boxes))
    np.fill_diagonal(probabilities, 0.0)
    return probabilities


def _summary(*arrays: np.ndarray) -> dict[str, Any]:
    """Row and column sums of each array (compared to a tolerance) and the SHA-256 of their bytes (exact)."""
    digest = hashlib.sha256()
    for array in arrays:
        digest.update(np.ascontiguousarray(array, dtype=np.float64).tobytes())
    return {
        "row_sums": [array.sum(axis=1).tolist() for array in arrays],
        "column_sums": [array.sum(axis=0).tolist() for array in arrays],
        "sha256": digest.hexdigest(),
    }


def golden_numbers() -> dict[str, Any]:
    """Every recorded number, computed by the present code (floats as Python floats: exact in JSON)."""
    import unstack
    from unstack.reasoner.sampling import sampled_marginals

    numbers: dict[str, Any] = {}
    for boxes, sweeps, seed in SAMPLED_CASES:
        result = sampled_marginals(_random_supports(boxes, seed), samples=sweeps, seed=seed)
        numbers[f"sampled_marginals/{boxes}"] = _summary(result.marginals, result.standard_errors)
    objects = [f"b{k}" for k in range(7)]
    exact = unstack.decide(unstack.Supports(objects, _random_supports(7, 4)), method="exact")
    numbers["decide/exact-7"] = {"choice": exact.choice, **_summary(exact.marginals)}
    stack5 = unstack.decide(unstack.load_supports(EXAMPLES / "stack5.supports.json"), seed=0)
    numbers["decide/stack5"] = {"choice": stack5.choice, "expected_costs": stack5.expected_costs.tolist()}
    sampled = unstack.decide(unstack.load_supports(EXAMPLES / "pile31.supports.json"), seed=0, samples=512)
    numbers["decide/pile31-sampled"] = {
        "choice": sampled.choice,
        "expected_costs": sampled.expected_costs.tolist(),
        "expected_cost_errors": np.asarray(sampled.expected_cost_errors).tolist(),
    }
    pile31 = unstack.plan(unstack.load_supports(EXAMPLES / "pile31.supports.json"), seed=0, samples=512)
    numbers["plan/pile31"] = {
        "order": list(pile31.order),
        "expected_costs": [step.expected_cost for step in pile31.steps],
    }
    scene = unstack.decide(unstack.load_scene(EXAMPLES / "pile5.scene.json"), seed=0)
    numbers["decide/pile5-scene"] = {"choice": scene.choice, "expected_costs": scene.expected_costs.tolist()}
    return numbers


def differences(recorded: Any, present: Any, path: str = "", *, tolerance: float = 0.0) -> list[str]:
    """Where ``present`` differs from ``recorded``: one line per JSON path (floats within ``tolerance``, relative).

    Examples
    --------
    >>> differences({"a": [1.0, 2.0]}, {"a": [1.0, 2.5]})
    ['a[1]: recorded 2.0, now 2.5']
    >>> differences({"a": [1.0]}, {"a": [1.0 + 1e-15]}, tolerance=1e-12)
    []
    """
    if isinstance(recorded, dict) and isinstance(present, dict):
        if tolerance:  # digests are exact by nature: another CPU is held to the sums alone
            recorded = {key: value for key, value in recorded.items() if key != "sha256"}
            present = {key: value for key, value in present.items() if key != "sha256"}
        if recorded.keys() != present.keys():
            return [f"{path or '.'}: keys {sorted(recorded)} recorded, {sorted(present)} now"]
        return [
            line
            for key in recorded
            for line in differences(
                recorded[key], present[key], f"{path}{'/' if path else ''}{key}", tolerance=tolerance
            )
        ]
    if isinstance(recorded, list) and isinstance(present, list):
        if len(recorded) != len(present):
            return [f"{path}: {len(recorded)} items recorded, {len(present)} now"]
        return [
            line
            for k, (a, b) in enumerate(zip(recorded, present, strict=True))
            for line in differences(a, b, f"{path}[{k}]", tolerance=tolerance)
        ]
    if isinstance(recorded, float) and isinstance(present, float):
        if recorded == present or abs(recorded - present) <= tolerance * max(abs(recorded), abs(present), 1e-300):
            return []
    elif recorded == present and type(recorded) is type(present):
        return []
    return [f"{path}: recorded {recorded!r}, now {present!r}"]


def main(arguments: list[str]) -> int:
    """Write the file (``--write``) or compare with it byte for byte; 1 when anything differs."""
    present = golden_numbers()
    if arguments == ["--write"]:
        GOLDEN_FILE.write_text(json.dumps(present) + "\n")
        print(f"wrote {GOLDEN_FILE}")
        return 0
    changed = differences(json.loads(GOLDEN_FILE.read_text()), present)
    print("\n".join(changed) if changed else "the same numbers, byte for byte")
    return 1 if changed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
