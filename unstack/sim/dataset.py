"""Simulated data sets: a folder of ``unstack.scene/1`` files and a manifest.

Layout of a data set folder::

    manifest.json                  unstack.dataset/1: settings, seed, size, versions, statistics
    config-0000.json               unstack.scene/1 (written last: its presence means "done")
    config-0000.points.npy         the point cloud (N x 3 float64)
    config-0000.point_boxes.npy    box index of every point (-1: container)
    timings.jsonl                  CPU seconds per phase and configuration (one line each)

Every file is written to a temporary name and renamed, so a killed run leaves no
half-written file, and re-running the same command skips the finished configurations:
at most the configurations in flight are lost. The configurations run in worker
processes (``jobs``) or on a dask.distributed cluster (``scheduler``); each one is seeded
from the data set's seed and its index only, so the files are bit-identical however they
were made.
A run holds the folder while it writes (:func:`unstack.atomic.folder_writer`): a second run on
the same folder at the same time is refused in one line instead of simulating every
configuration again.

Examples
--------
>>> import tempfile
>>> from unstack.sim.settings import Container, SensorSettings, SimulationSettings
>>> settings = SimulationSettings(boxes=(3, 4), container=Container(depth=1.0),
...                               sensor=SensorSettings(width=80, height=60, min_pixels=5))
>>> folder = tempfile.mkdtemp()
>>> summary = simulate_dataset(folder, settings, configs=2, seed=3)
>>> summary.finished, len(list_configurations(folder))
(2, 2)
"""

from __future__ import annotations

import asyncio
import concurrent.futures
import contextlib
import json
import os
import re
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import numpy as np

from unstack.atomic import atomic_save_array, atomic_write_text, check_folder_path, folder_writer
from unstack.dataset_folders import DATASET_FORMAT, MANIFEST, TIMINGS, config_name, list_configurations, read_manifest
from unstack.errors import InvalidArgument, UnstackError
from unstack.parameters import MAX_CONFIGS, MAX_JOBS
from unstack.sim.configuration import SimulatedConfiguration, simulate_configuration
from unstack.sim.settings import MIN_PILE_BOXES, SimulationSettings, json_ready

__all__ = [
    "DatasetConflict",
    "DatasetSummary",
    "SchedulerUnavailable",
    "check_jobs_or_scheduler",
    "check_scheduler_address",
    "connect_scheduler",
    "scheduler_client",
    "simulate_dataset",
]

SCHEDULER_ADDRESS = re.compile(r"^(?:tcp://)?[^\s:/]+:(?P<port>\d+)$")
#: dask's other transports and what each needs beyond an address.
SCHEDULER_TRANSPORTS = {
    "tls": "security settings",
    "wss": "security settings",
    "ws": "websocket settings",
    "ucx": "UCX settings",
    "inproc": "scheduler in this process",
}
#: The largest TCP port.
MAX_PORT = 65535
#: Seconds to wait for a dask scheduler before saying it does not answer.
SCHEDULER_TIMEOUT = 5.0


class DatasetConflict(UnstackError):
    """The output folder holds another data set."""


class SchedulerUnavailable(UnstackError):
    """The dask scheduler address does not answer."""


@dataclass(frozen=True)
class DatasetSummary:
    """What a run of :func:`simulate_dataset` did.

    Attributes
    ----------
    folder : pathlib.Path
    finished : int
        Configurations on disk after the run.
    skipped : int
        Configurations that were already there.
    made : int
        Configurations made by this run.
    seconds : float
        Wall time of the run.
    """

    folder: Path
    finished: int
    skipped: int
    made: int
    seconds: float


def _check_resumable(folder: Path, settings: SimulationSettings, seed: int) -> None:
    """Refuse a folder whose configurations another data set made: a manifest of other settings or
    another seed, or configurations with no manifest (a run writes its manifest before its first
    configuration, so these are no run of this command). A manifest alone: a run stopped before
    its first configuration."""
    found = list_configurations(folder)
    if not found:
        return
    manifest = read_manifest(folder)
    if manifest is None:
        raise DatasetConflict(
            f"{folder}: holds {len(found):,} configuration file(s) ({found[0].name}, ...) and no {MANIFEST}: no data "
            "set this command made or can add to; choose another folder"
        )
    _check_same_dataset(folder, manifest, settings, seed)


def _check_same_dataset(folder: Path, manifest: dict[str, Any], settings: SimulationSettings, seed: int) -> None:
    theirs = manifest.get("settings")
    ours = settings.to_dict()
    if manifest.get("seed") != seed:
        raise DatasetConflict(
            f"{folder / MANIFEST}: $.seed: the folder holds another data set (seed {manifest.get('seed')}, "
            f"asked for {seed}); choose another folder"
        )
    if theirs != ours:
        differing = sorted(key for key in ours if theirs is None or theirs.get(key) != ours.get(key))
        raise DatasetConflict(
            f"{folder / MANIFEST}: $.settings: the folder holds another data set "
            f"(settings differ in {', '.join(differing)}); choose another folder"
        )


def _write_manifest(folder: Path, settings: SimulationSettings, seed: int, configs: int) -> None:
    from unstack.provenance import package_versions
    from unstack.sim.configuration import SIMULATION_PACKAGES

    existing = (read_manifest(folder) or {}) if list_configurations(folder) else {}  # else another run's, replaced
    manifest = {
        "format": DATASET_FORMAT,
        "seed": seed,
        "configs": max(configs, int(existing.get("configs", 0))),
        "settings": settings.to_dict(),
        "created": existing.get("created", datetime.now(UTC).isoformat(timespec="seconds")),
        "versions": package_versions(*SIMULATION_PACKAGES),
    }
    if "statistics" in existing:
        manifest["statistics"] = existing["statistics"]
    atomic_write_text(folder / MANIFEST, json.dumps(manifest, indent=2) + "\n")


def _save_configuration(folder: Path, result: SimulatedConfiguration) -> None:
    stem = config_name(result.index)
    atomic_save_array(folder / f"{stem}.point_boxes.npy", result.point_boxes.astype(np.int32))
    result.scene.save(folder / f"{stem}.json", points_file=f"{stem}.points.npy")
    _append_timings(folder / TIMINGS, {"index": result.index, **{k: round(v, 4) for k, v in result.timings.items()}})


def _append_timings(path: Path, record: dict[str, Any]) -> None:
    """Add one line to the timings log by rewriting it whole (atomically: never a half line)."""
    previous = path.read_text(encoding="utf-8") if path.exists() else ""
    atomic_write_text(path, previous + json.dumps(record) + "\n")


def _statistics(folder: Path) -> dict[str, Any]:
    """Per-data-set statistics from the finished scene files (labels, transitivity)."""
    violated = premises = supports = pairs = detectable = boxes = 0
    for path in list_configurations(folder):
        data = json.loads(path.read_text())
        simulation = data["metadata"]["simulation"]
        violated += simulation["transitivity"]["violated"]
        premises += simulation["transitivity"]["premises"]
        truth = np.asarray(data["ground_truth"]["support"])
        supports += int(truth.sum())
        pairs += truth.shape[0] * (truth.shape[0] - 1)
        detectable += len(data["detected"])
        boxes += len(data["boxes"])
    return {
        "configurations": len(list_configurations(folder)),
        "boxes": boxes,
        "detectable_boxes": detectable,
        "support_relations": supports,
        "ordered_pairs": pairs,
        "transitivity_premises": premises,
        "transitivity_violated": violated,
        "transitivity_violated_share": round(violated / premises, 4) if premises else 0.0,
    }


def _clean_temporaries(folder: Path) -> None:
    for path in folder.glob(".*.tmp*"):
        path.unlink(missing_ok=True)


def _run_local(todo: list[int], settings: SimulationSettings, seed: int, jobs: int) -> Iterator[SimulatedConfiguration]:
    if jobs == 1:
        for index in todo:
            yield simulate_configuration(settings, seed=seed, index=index)
        return
    from joblib import Parallel, delayed

    parallel = Parallel(n_jobs=jobs, return_as="generator_unordered", backend="loky")
    yield from parallel(delayed(simulate_configuration)(settings, seed=seed, index=index) for index in todo)


def check_scheduler_address(address: str) -> str:
    """``address`` if it names a dask scheduler unstack can reach: ``tcp://HOST:PORT`` or
    ``HOST:PORT``, the port from 1 to 65535; else :class:`~unstack.errors.InvalidArgument`.

    ``tls://`` (and dask's other transports) need security or transport settings that unstack
    does not take, so they are refused here rather than failing inside dask.

    Examples
    --------
    >>> check_scheduler_address("tcp://10.0.0.5:8786")
    'tcp://10.0.0.5:8786'
    >>> try:
    ...     check_scheduler_address("tls://10.0.0.5:8786")
    ... except ValueError as error:
    ...     print(error)
    scheduler: tls:// needs dask's security settings, which unstack does not take; give a tcp://HOST:PORT address
    """
    scheme, separator, _ = address.partition("://")
    if separator and scheme != "tcp" and scheme in SCHEDULER_TRANSPORTS:
        raise InvalidArgument(
            f"scheduler: {scheme}:// needs dask's {SCHEDULER_TRANSPORTS[scheme]}, which unstack does not take; "
            "give a tcp://HOST:PORT address"
        )
    found = SCHEDULER_ADDRESS.match(address)
    if found is None:
        raise InvalidArgument(f"scheduler: expected an address like tcp://HOST:PORT, got {address!r}")
    if not 1 <= int(found["port"]) <= MAX_PORT:
        raise InvalidArgument(f"scheduler: expected a port from 1 to {MAX_PORT}, got {found['port']} in {address!r}")
    return address


def check_jobs_or_scheduler(jobs: int, scheduler: str | None) -> None:
    """Refuse local processes (``jobs`` above 1) asked for beside a scheduler, whose workers run
    the tasks: one of them would be passed over without a word.

    Examples
    --------
    >>> check_jobs_or_scheduler(1, "tcp://10.0.0.5:8786")
    >>> try:
    ...     check_jobs_or_scheduler(2, "tcp://10.0.0.5:8786")
    ... except ValueError as error:
    ...     print(error)
    jobs: 2 local processes and a scheduler exclude each other (its workers run the tasks); give one of them
    """
    if scheduler is not None and jobs != 1:
        raise InvalidArgument(
            f"jobs: {jobs} local processes and a scheduler exclude each other (its workers run the tasks); "
            "give one of them"
        )


async def _handshake(address: str) -> None:
    """Connect to ``address`` (within :data:`SCHEDULER_TIMEOUT`) and exchange dask's handshake
    (within twice that in all): dask bounds the connection but waits for the handshake's answer
    for ever."""
    from distributed.comm.core import connect

    async def exchange() -> None:
        comm = await connect(address, timeout=SCHEDULER_TIMEOUT)  # type: ignore[no-untyped-call]
        await comm.close()

    await asyncio.wait_for(exchange(), 2 * SCHEDULER_TIMEOUT)  # dask's own time limit ends first


def connect_scheduler(scheduler: str) -> Any:
    """A dask.distributed client, or a one-line error: the address refused at once
    (:func:`check_scheduler_address`), nothing answering there after :data:`SCHEDULER_TIMEOUT`, or
    something answering that is no dask scheduler after twice that."""
    check_scheduler_address(scheduler)
    try:
        from distributed import Client
    except ImportError as error:  # pragma: no cover - depends on the installation
        raise UnstackError("a dask scheduler needs dask.distributed: pip install 'unstack[sim]'") from error
    try:  # in a thread of its own: the caller may be running an event loop (a notebook)
        with concurrent.futures.ThreadPoolExecutor(1) as pool:
            pool.submit(asyncio.run, _handshake(scheduler)).result()
    except TimeoutError as error:
        raise SchedulerUnavailable(
            f"{scheduler} answers but not as a dask scheduler (no handshake within {2 * SCHEDULER_TIMEOUT:g} s)"
        ) from error
    except OSError as error:
        raise SchedulerUnavailable(
            f"dask scheduler {scheduler} does not answer within {SCHEDULER_TIMEOUT:g} s ({type(error).__name__})"
        ) from error
    try:
        return Client(scheduler, timeout=SCHEDULER_TIMEOUT, set_as_default=False)  # type: ignore[no-untyped-call]
    except (OSError, TimeoutError, ValueError) as error:
        raise SchedulerUnavailable(
            f"dask scheduler {scheduler} does not answer within {SCHEDULER_TIMEOUT:g} s ({type(error).__name__})"
        ) from error


@contextlib.contextmanager
def scheduler_client(scheduler: str | None, jobs: int = 1) -> Iterator[Any]:
    """A dask.distributed client for the address ``scheduler`` (None: no client), closed on exit.

    ``jobs``, the local processes asked for beside it, must be 1: the scheduler's workers run the
    tasks (:func:`check_jobs_or_scheduler`).

    Connects on entry (:func:`connect_scheduler`: a one-line error within
    :data:`SCHEDULER_TIMEOUT`), so a command that enters it before writing anything fails
    before any output.

    Examples
    --------
    >>> with scheduler_client(None) as client:
    ...     client is None
    True
    """
    check_jobs_or_scheduler(jobs, scheduler)
    client = connect_scheduler(scheduler) if scheduler is not None else None
    try:
        yield client
    finally:
        if client is not None:
            client.close()


def _run_dask(
    todo: list[int], settings: SimulationSettings, seed: int, client: Any
) -> Iterator[SimulatedConfiguration]:
    from distributed import as_completed

    with client.as_current():
        futures = [
            client.submit(
                simulate_configuration, settings, seed=seed, index=index, pure=False, key=f"unstack-{seed}-{i}"
            )
            for i, index in enumerate(todo)
        ]
        for future in as_completed(futures):  # type: ignore[no-untyped-call]
            yield future.result()


def simulate_dataset(
    folder: str | os.PathLike[str],
    settings: SimulationSettings,
    *,
    configs: int,
    seed: int,
    jobs: int = 1,
    scheduler: str | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> DatasetSummary:
    """Make (or finish) a simulated data set of ``configs`` configurations in ``folder``.

    Parameters
    ----------
    folder : path
        Created if missing. A folder holding another data set (other seed or settings)
        is refused with :class:`DatasetConflict`.
    settings : SimulationSettings
    configs : int
        Configurations the data set should hold.
    seed : int
    jobs : int
        Worker processes on this machine.
    scheduler : str, optional
        Address of a dask.distributed scheduler; the configurations run on its workers.
    progress : callable, optional
        Called as ``progress(done, total)`` after each configuration (the CLI draws a bar).

    Returns
    -------
    DatasetSummary
    """
    if not 1 <= configs <= MAX_CONFIGS:
        raise UnstackError(f"configs must be from 1 to {MAX_CONFIGS:,}, got {configs}")
    if not 1 <= jobs <= MAX_JOBS:
        raise UnstackError(f"jobs must be from 1 to {MAX_JOBS}, got {jobs}")
    if settings.boxes[0] < MIN_PILE_BOXES:
        low, high = settings.boxes
        raise UnstackError(
            f"settings.boxes: {low}-{high}: a pile of one box supports nothing; a data set needs at least "
            f"{MIN_PILE_BOXES} a pile"
        )
    start = time.perf_counter()
    target = Path(folder)
    if target.exists() and not target.is_dir():
        raise DatasetConflict(f"{target}: expected a folder for the data set, got a file")
    check_folder_path(target, "the data set")
    if target.is_dir():
        _check_resumable(target, settings, seed)
    check_jobs_or_scheduler(jobs, scheduler)
    client = connect_scheduler(scheduler) if scheduler is not None else None
    target.mkdir(parents=True, exist_ok=True)
    try:
        with folder_writer(target, "a data set", DatasetConflict):
            return _fill_dataset(target, settings, configs, seed, jobs, client, progress, start)
    finally:
        if client is not None:
            client.close()


def _fill_dataset(
    target: Path,
    settings: SimulationSettings,
    configs: int,
    seed: int,
    jobs: int,
    client: Any,
    progress: Callable[[int, int], None] | None,
    start: float,
) -> DatasetSummary:
    """:func:`simulate_dataset`'s work in a folder it holds: the configurations still missing."""
    _check_resumable(target, settings, seed)  # again, now that no other run writes the folder
    _clean_temporaries(target)
    _write_manifest(target, settings, seed, configs)
    done = {int(path.stem.split("-")[1]) for path in list_configurations(target)}
    todo = [index for index in range(configs) if index not in done]
    skipped = configs - len(todo)
    made = 0
    results = _run_dask(todo, settings, seed, client) if client else _run_local(todo, settings, seed, jobs)
    if progress is not None:
        progress(skipped, configs)
    for result in results:
        _save_configuration(target, result)
        made += 1
        if progress is not None:
            progress(skipped + made, configs)
    manifest = read_manifest(target) or {}
    manifest["statistics"] = _statistics(target)
    atomic_write_text(target / MANIFEST, json.dumps(json_ready(manifest), indent=2) + "\n")
    return DatasetSummary(target, len(list_configurations(target)), skipped, made, time.perf_counter() - start)
