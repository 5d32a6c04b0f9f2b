"""Decisions from several Python threads at once equal the serial ones and never abort.

Every compiled kernel (the sampler's chains, the exact walk, the DBAF and contact-feature
counts) runs GIL-free on threads of its call (:mod:`unstack.threads`); numba's threading layer
is never started, so a decision leaves the process as it found it.
"""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import unstack
from unstack.threads import even_ranges, map_on_threads


def _dense(n: int, seed: int) -> unstack.Supports:
    rng = np.random.default_rng(seed)
    p = rng.uniform(0.05, 0.95, (n, n))
    np.fill_diagonal(p, 0.0)
    return unstack.Supports([f"b{i}" for i in range(n)], p)


def _jobs(examples: Path) -> list[tuple[Any, dict[str, Any]]]:
    scene = unstack.load_scene(examples / "pile5.scene.json")
    return [
        (_dense(20, 1), {"seed": 3, "samples": 2048}),  # sampled: the parallel sampler kernel
        (_dense(7, 2), {"method": "exact"}),  # the compiled exact walk (its own threads)
        (_dense(5, 3), {}),  # the table path
        (scene, {"model": "extended"}),  # features: the contact and DBAF kernels
        (_dense(12, 4), {"seed": 5, "samples": 1024, "method": "approx"}),
        (scene, {}),
    ]


def _summary(decision: unstack.Decision) -> tuple[str, list[float], list[float]]:
    errors = decision.expected_cost_errors
    return decision.choice, decision.expected_costs.tolist(), [] if errors is None else errors.tolist()


@pytest.mark.slow  # runs decisions in four threads
def test_four_threads_give_the_serial_answers(examples: Path) -> None:
    jobs = _jobs(examples)
    serial = [_summary(unstack.decide(subject, **options)) for subject, options in jobs]
    work = jobs * 3
    with ThreadPoolExecutor(max_workers=4) as pool:
        concurrent = list(pool.map(lambda job: _summary(unstack.decide(job[0], **job[1])), work))
    assert concurrent == serial * 3


_NUMBERS_OF_A_RUN = """
import hashlib, sys
import numpy as np
import unstack
from unstack.reasoner.sampling import sampled_marginals
rng = np.random.default_rng(7)
digest = hashlib.sha256()
for n, samples in ((40, 2048), (70, 256)):  # one-word and word-array kernels
    p = rng.uniform(0.0, 0.3, (n, n)); np.fill_diagonal(p, 0.0)
    result = sampled_marginals(p, samples=samples, seed=3)
    digest.update(result.marginals.tobytes()); digest.update(result.standard_errors.tobytes())
scene = unstack.load_scene(sys.argv[1])
digest.update(unstack.support_probabilities(scene, "extended").probabilities.tobytes())  # DBAF and contact counts
print(digest.hexdigest())
"""


@pytest.mark.slow  # runs decisions in four threads
def test_the_numbers_do_not_depend_on_the_number_of_threads(examples: Path) -> None:
    import os
    import subprocess
    import sys

    digests = set()
    for threads in ("1", "2", "3"):
        environment = {**os.environ, "NUMBA_NUM_THREADS": threads}
        command = [sys.executable, "-c", _NUMBERS_OF_A_RUN, str(examples / "pile5.scene.json")]
        digests.add(subprocess.run(command, env=environment, capture_output=True, text=True, check=True).stdout)
    assert len(digests) == 1


@pytest.mark.slow  # runs decisions in four threads
def test_a_decision_starts_no_threading_layer_and_leaves_multiprocessing_alone(examples: Path) -> None:
    import subprocess
    import sys

    program = f"""
import multiprocessing, threading
import numpy as np
import unstack
from numba.np.ufunc import parallel
dense = np.random.default_rng(0).uniform(0.05, 0.95, (20, 20)); np.fill_diagonal(dense, 0.0)
unstack.decide(unstack.Supports([f"b{{i}}" for i in range(20)], dense), seed=3, samples=1024)
unstack.decide(unstack.Supports([f"b{{i}}" for i in range(7)], dense[:7, :7]), method="exact")
unstack.decide(unstack.load_scene({str(examples / "pile5.scene.json")!r}), model="extended")
assert not parallel._is_initialized, "numba's threading layer was started"
assert multiprocessing.get_start_method(allow_none=True) is None, "the start method was fixed"
multiprocessing.set_start_method("spawn")
assert not [t.name for t in threading.enumerate() if t.name.startswith("unstack-")], "threads left running"
print("ok")
"""
    result = subprocess.run([sys.executable, "-c", program], capture_output=True, text=True)
    assert result.returncode == 0, result.stderr[-2000:]
    assert result.stdout.strip() == "ok"


@pytest.mark.slow  # loads shipped models in fresh interpreters
@pytest.mark.parametrize(
    ("program", "expected"),
    [
        (  # four threads asking for a model no thread has loaded yet
            "from concurrent.futures import ThreadPoolExecutor\n"
            "with ThreadPoolExecutor(4) as pool:\n"
            "    models = list(pool.map(lambda _: unstack.load_model('paper'), range(4)))\n"
            "print(len({id(model) for model in models}))",
            "1",
        ),
        (  # the default model asked for by its name first, then decided with as the default
            "unstack.load_model('general')\n"
            "print(unstack.decide(unstack.load_scene(EXAMPLE), seed=1).to_dict()['model'])",
            "default:general-mix.skops",
        ),
    ],
    ids=["one-load-for-four-threads", "label-whatever-came-first"],
)
def test_a_shipped_model_is_loaded_once_and_named_the_same_whoever_asked_first(
    examples: Path, program: str, expected: str
) -> None:
    """Four threads' first loads read four copies; the default model asked for by name first was
    recorded as 'shipped:' in every later decision of the process (another to_dict for one call)."""
    import subprocess
    import sys

    code = f"import unstack\nEXAMPLE = {str(examples / 'pile5.scene.json')!r}\n{program}\n"
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert result.returncode == 0, result.stderr[-2000:]
    assert result.stdout.strip() == expected


def test_even_ranges_cover_every_item_once() -> None:
    for items in range(0, 12):
        for parts in range(1, 6):
            ranges = even_ranges(items, parts)
            assert [i for first, last in ranges for i in range(first, last)] == list(range(items))
            assert len(ranges) == max(1, min(parts, items))
            assert max(last - first for first, last in ranges) - min(last - first for first, last in ranges) <= 1


def test_map_on_threads_keeps_the_order_and_uses_numbas_threads() -> None:
    import threading

    import numba

    seen_threads = set()

    def square_slowly(item: int) -> int:
        seen_threads.add(threading.get_ident())
        threading.Event().wait(0.01 * (8 - item))  # late items finish first
        return item * item

    assert map_on_threads(square_slowly, range(8)) == [item * item for item in range(8)]
    assert len(seen_threads) == min(numba.get_num_threads(), 8)


def test_map_on_threads_runs_in_the_calling_thread_when_numba_may_use_one() -> None:
    import threading

    import numba

    def worker() -> set[int]:
        numba.set_num_threads(1)  # local to this thread
        seen = set()
        map_on_threads(lambda item: seen.add(threading.get_ident()), range(4))
        return seen | {threading.get_ident()}

    with ThreadPoolExecutor(max_workers=1) as pool:
        assert len(pool.submit(worker).result()) == 1


def test_map_on_threads_raises_the_first_error_and_drops_the_items_not_started() -> None:
    import threading

    import numba

    if numba.get_num_threads() < 2:
        pytest.skip("one kernel thread: items run in the calling thread")
    started = []

    def fail_first(item: int) -> int:
        started.append(item)
        if item == 0:
            raise ValueError("item 0 failed")
        threading.Event().wait(0.05)
        return item

    with pytest.raises(ValueError, match="item 0 failed"):
        map_on_threads(fail_first, range(200))
    assert len(started) < 200
