"""Shared fixtures and helpers: seeded random probability matrices, example files, the CLI in a subprocess."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from unstack.scene import Box
from unstack.supports import Supports

REPO = Path(__file__).resolve().parents[1]
EXAMPLES = REPO / "examples"
#: The five-box example supports file, relative to the repository (the CLI runs there).
PILE5 = "examples/stack5.supports.json"

# The suite runs on every core (pytest-xdist, ``-n auto``): one OpenMP thread per worker and per
# CLI subprocess, or scikit-learn's boosting oversubscribes the cores and a 6 s fit takes a minute.
if "PYTEST_XDIST_WORKER" in os.environ:
    os.environ.setdefault("OMP_NUM_THREADS", "1")


def pytest_sessionstart(session: pytest.Session) -> None:
    """Compile numba's kernels once, two at a time, before the workers start.

    On an empty cache (a fresh install, CI) every worker and CLI subprocess that needs a kernel
    would compile it itself, the same kernel in several processes at once: measured, the whole
    suite took 602 s instead of 462 s. A worker (``workerinput``) finds them compiled.
    """
    if hasattr(session.config, "workerinput"):
        return
    from unstack.warmup import warm_up

    warm_up(jobs=2)


def unstack(
    *args: str, stdin: str | None = None, cwd: Path | None = None, env: dict[str, str] | None = None
) -> subprocess.CompletedProcess[str]:
    """Run ``python -m unstack ARGS`` in the repository (or ``cwd``, with ``env`` added); output as text."""
    return subprocess.run(
        [sys.executable, "-m", "unstack", *args],
        input=stdin,
        capture_output=True,
        text=True,
        cwd=cwd or REPO,
        timeout=300,
        env=None if env is None else {**os.environ, **env},
    )


def assert_one_line_error(
    result: subprocess.CompletedProcess[str], *messages: str, nothing_written_in: Path | None = None
) -> None:
    """The CLI's answer to bad input: exit code 2, one line naming each of ``messages``, no file left behind."""
    assert result.returncode == 2 and result.stderr.count("\n") == 1, result.stderr
    for message in messages:
        assert message in result.stderr, result.stderr
    if nothing_written_in is not None:
        assert not list(nothing_written_in.iterdir())


def random_probabilities(n: int, rng: np.random.Generator, *, hard: float = 0.0) -> np.ndarray:
    """Off-diagonal p ~ U(0.05, 0.95); a share ``hard`` of pairs set to exactly 0."""
    probabilities = rng.uniform(0.05, 0.95, size=(n, n))
    if hard:
        probabilities[rng.random((n, n)) < hard] = 0.0
    np.fill_diagonal(probabilities, 0.0)
    return probabilities


def weak_groups(
    rng: np.random.Generator,
    sizes: list[int],
    link: float,
    *,
    inside: tuple[float, float] = (0.05, 0.95),
    strong: float = 0.0,
) -> np.ndarray:
    """Dense groups of the given sizes (``U(*inside)`` inside), every pair across ``link``.

    With ``strong`` > 0, that share of the pairs inside a group (drawn) is ``U(0.5, 0.95)`` instead.
    """
    n = sum(sizes)
    probabilities = np.full((n, n), link)
    start = 0
    for size in sizes:
        block = slice(start, start + size)
        probabilities[block, block] = rng.uniform(*inside, (size, size))
        if strong:
            chosen = rng.random((size, size)) < strong
            probabilities[block, block][chosen] = rng.uniform(0.5, 0.95, int(chosen.sum()))
        start += size
    np.fill_diagonal(probabilities, 0.0)
    return probabilities


def supports_of(probabilities: np.ndarray) -> Supports:
    return Supports([f"b{i}" for i in range(len(probabilities))], probabilities)


#: Modules whose doctests run experiments or simulate whole piles: slow. The other doctests take
#: milliseconds each (a physics world of two boxes, the shipped model loaded once per worker) and
#: run in the fast lane too.
SLOW_DOCTEST_PACKAGES = (
    "unstack/experiments/",
    "unstack/sim/dataset.py",
    "unstack/sim/piles.py",
)


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """Mark the doctests of :data:`SLOW_DOCTEST_PACKAGES` slow (a doctest cannot carry a marker)."""
    for item in items:
        path = item.path.as_posix()
        if isinstance(item, pytest.DoctestItem) and any(part in path for part in SLOW_DOCTEST_PACKAGES):
            item.add_marker(pytest.mark.slow)


#: Randomised tests run once per seed: an invariant that holds for one draw only is caught.
#: Tests marked slow run for the first seed only (the suite must stay under 10 minutes).
SEEDS = (20261122, 1, 2)


def pytest_generate_tests(metafunc: pytest.Metafunc) -> None:
    """Give every test that takes ``rng`` one run per seed of :data:`SEEDS` (slow tests: the first)."""
    if "rng" in metafunc.fixturenames:
        seeds = SEEDS[:1] if metafunc.definition.get_closest_marker("slow") else SEEDS
        metafunc.parametrize("rng", seeds, indirect=True, ids=[f"seed{seed}" for seed in seeds])


@pytest.fixture
def rng(request: pytest.FixtureRequest) -> np.random.Generator:
    """A seeded generator; see :func:`pytest_generate_tests` for the seeds."""
    return np.random.default_rng(request.param)


@pytest.fixture
def fixed_rng() -> np.random.Generator:
    """One seeded generator, for tests whose fits are too slow to repeat per seed."""
    return np.random.default_rng(SEEDS[0])


@pytest.fixture
def repo() -> Path:
    return REPO


@pytest.fixture
def examples() -> Path:
    return EXAMPLES


@pytest.fixture(scope="session")
def small_dataset(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A simulated data set of eight small piles (7-9 boxes), made once per test session."""
    from unstack.sim.dataset import simulate_dataset
    from unstack.sim.settings import Container, GroundTruthSettings, SensorSettings, SimulationSettings

    folder = tmp_path_factory.mktemp("small-dataset")
    settings = SimulationSettings(
        boxes=(7, 9),
        sizes="four",
        container=Container(depth=1.0),
        ground_truth=GroundTruthSettings(horizon=0.5),
        sensor=SensorSettings(width=160, height=120, min_pixels=10),
    )
    simulate_dataset(folder, settings, configs=8, seed=5)
    return folder


@pytest.fixture
def hidden_step() -> list[Box]:
    """A tall front box hiding a low box behind it, and a box on the low one showing above it
    (seen from the simulator's default sensor position)."""
    return [
        Box("front", [0.4, 0.6, 0.4], [0.6, 0.0, 0.2]),
        Box("under", [0.4, 0.6, 0.3], [1.0, 0.0, 0.15]),
        Box("up", [0.4, 0.6, 0.3], [1.0, 0.0, 0.45]),
    ]
