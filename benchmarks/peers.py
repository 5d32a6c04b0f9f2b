"""Side by side: unstack's methods against ProbLog, PySDD and Ganak on the same instances.

Every method answers the same question -- ``P(S_xy = 1 | consistent)`` for every ordered
pair -- on the matrices of :mod:`instances` (``dense`` and ``sparse``, seeded random;
``classifier``, the shipped classifier on simulated piles of 31-40 boxes):

``exact``
    ``unstack.decide(supports, method="exact")``: weighted counting of preorders (numba,
    parallel over the machine's cores).
``exact-1t``
    the same with ``NUMBA_NUM_THREADS=1``: one core, like the peers.
``sat``
    ``unstack.decide(supports, method="sat")``: lists the worlds with CaDiCaL (n <= 6).
``approx``
    ``unstack.reasoner.decision.decide(supports, method="approx", time_limit=T, seed=0)``
    with ``T = --approx-seconds`` (default 1 s): MCMC over consistent worlds, so it takes
    about ``T`` at every size and runs every size. Not exact: it is scored against exact
    by its largest marginal difference and its largest EC error, ``max_i |sum_j
    approx[i, j] - sum_j exact[i, j]|`` (Eq. 11's count cost), next to its own largest
    EC standard error -- never flagged as a disagreement.
``problog``
    ProbLog 2 through its Python API with its default knowledge compiler (SDD when PySDD is
    installed): ``p::s(X,Y).`` per ordered pair, ``inconsistent :- s(X,Y), s(Y,Z), X \\= Z,
    \\+ s(X,Z).``, ``evidence(inconsistent, false).`` and ``query(s(X,Y)).`` per pair.
``pysdd``
    PySDD directly: the transitivity constraint (one clause ``-s_xy | -s_yz | s_xz`` per
    ordered triple) compiled bottom-up into an SDD over the ``n(n-1)`` pair variables, then
    one weighted model count with literal weights ``p`` and ``1 - p`` (log mode) and every
    conditional marginal from ``WmcManager.literal_pr`` after one ``propagate()``.
``pyganak``
    Ganak (Arjun preprocessing, exact weighted model counting in 128-bit MPFR) through
    PyPI's ``pyganak``: the same CNF, one variable per ordered pair with literal weights
    ``p`` and ``1 - p`` divided by ``max(p, 1 - p)`` (the ratios are unchanged, the counts
    stay far from float64's underflow), and ``m + 1`` counts for ``m = n(n-1)`` pairs:
    ``Z``, then ``Z_xy`` with the unit clause ``s_xy`` added, ``P = Z_xy / Z``. A counter
    counts once, so each count builds its own. ``count()`` returns a float64: when ``Z``
    still underflows (or overflows) the result's status is ``underflow``, not numbers.

The exact methods (all but ``approx``) must agree with unstack exact to
:data:`AGREE_TOLERANCE` (``1e-9``) on every marginal; a larger difference is flagged
``DISAGREES`` in the table and the script exits with status 1.

Sizes. ``exact``/``exact-1t`` skip ``n`` above unstack's exact limit (8, or
``--max-boxes``), ``sat`` above 6, a ``classifier`` size above its pile's box count. Every
exact method also skips, per family, every size above the first at which it timed out, ran
out of memory or underflowed (sizes run in increasing order); ``approx`` runs every size.
A method that cannot be imported is tried once per family. A summary after the tables
gives, per family and method, the largest ``n`` within the timeout.

Each (method, family, n) runs in its own subprocess with a timeout and an address-space
limit; the parent reads the child's peak RSS from ``os.wait4``. Inside the child the first
call is timed alone (for unstack it includes loading numba's cached machine code), then the
call is repeated while that stays cheap; the best repeat is the *compute* time. *End to
end* runs from spawning the subprocess to the first answer: interpreter start, imports
and the first call (for the CLI user this is what a single run costs). Peak RSS is the
subprocess's maximum resident set over all its calls. Ratios divide by unstack exact's
figure of the same instance measured in the same run.

Usage::

    python benchmarks/peers.py --sizes 3-7 --families dense,sparse --timeout 120 --seed 0 --json out.json
    python benchmarks/peers.py --sizes 3-8,10,20,30,40 --families dense,sparse,classifier
    python benchmarks/peers.py --sizes 20,40 --methods approx --approx-seconds 2

``--methods`` picks a subset (unstack exact always runs: it is the reference of every
difference and ratio).

The worker mode (``--worker``) is internal.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import platform
import resource
import signal
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

HERE = Path(__file__).resolve().parent
if str(HERE) not in sys.path:
    sys.path.insert(0, str(HERE))

from bench_table import seconds_text  # noqa: E402
from instances import ALL_FAMILIES, box_ids, instance  # noqa: E402

from unstack.atomic import atomic_write_text  # noqa: E402

METHODS: tuple[str, ...] = ("exact", "exact-1t", "sat", "approx", "problog", "pysdd", "pyganak")
LABELS: dict[str, str] = {
    "exact": "exact",
    "exact-1t": "exact 1 thread",
    "sat": "sat",
    "approx": "approx",
    "problog": "ProbLog",
    "pysdd": "PySDD",
    "pyganak": "Ganak",
}
#: Methods whose marginals are estimates: scored against exact, never flagged.
APPROXIMATE: frozenset[str] = frozenset({"approx"})
#: Below this acceptance rate the approx row warns that its chains barely moved.
STUCK_ACCEPTANCE = 0.01
#: Largest marginal difference an exact method may have from unstack exact.
AGREE_TOLERANCE = 1e-9
#: unstack's SAT enumeration refuses more boxes than this.
SAT_MAX_BOXES = 6
#: unstack's exact engine refuses more boxes than this unless ``--max-boxes`` raises it
#: (``unstack.reasoner.marginals.EXACT_MAX_BOXES``).
EXACT_MAX_BOXES = 8
#: Repeat a call only while one call takes less than this (seconds).
REPEAT_BELOW_SECONDS = 20.0


@dataclass
class Outcome:
    """One method on one instance."""

    method: str
    family: str
    n: int
    seed: int
    status: str = "ok"  # ok | timeout | memory | underflow | error | skipped
    reason: str = ""
    first_seconds: float | None = None
    seconds: float | None = None
    calls: int = 0
    phases: dict[str, float] = field(default_factory=dict)
    import_seconds: float | None = None
    first_done_at: float | None = None  # time.time() when the first call returned
    end_to_end_seconds: float | None = None  # from spawning the subprocess to the first answer
    wall_seconds: float | None = None  # the whole subprocess, every repeat included
    max_rss_mib: float | None = None
    max_abs_diff: float | None = None
    max_ec_error: float | None = None  # max_i |sum_j marginals[i, j] - sum_j exact[i, j]|
    agrees: bool | None = None  # exact methods: max_abs_diff <= AGREE_TOLERANCE
    ratio: float | None = None
    wall_ratio: float | None = None
    details: dict[str, Any] = field(default_factory=dict)
    marginals: list[list[float]] | None = None


# --------------------------------------------------------------------------- workers
# Each returns (marginals, timings, details) for one call on one matrix.

CallResult = tuple[np.ndarray, dict[str, float], dict[str, Any]]


def run_unstack(method: str, probabilities: np.ndarray, max_boxes: int | None) -> CallResult:
    from unstack.reasoner.decision import decide
    from unstack.supports import Supports

    supports = Supports(box_ids(len(probabilities)), probabilities)
    decision = decide(supports, method=method, max_boxes=max_boxes)
    return decision.marginals, {}, {"consistent_worlds": decision.consistent_worlds, "choice": decision.choice}


def run_approx(probabilities: np.ndarray, seconds: float) -> CallResult:
    from unstack.reasoner.decision import decide
    from unstack.supports import Supports

    supports = Supports(box_ids(len(probabilities)), probabilities)
    decision = decide(supports, method="approx", time_limit=seconds, seed=0)
    sampling = decision.sampling or {}
    details: dict[str, Any] = {"choice": decision.choice, "component_methods": list(decision.component_methods)}
    details |= {key: sampling.get(key) for key in ("chains", "samples", "burn_in", "acceptance")}
    if decision.expected_cost_errors is not None:
        details["max_ec_standard_error"] = float(np.max(decision.expected_cost_errors))
    if decision.marginal_errors is not None:
        details["max_marginal_standard_error"] = float(np.max(decision.marginal_errors))
    timings = {"sample": float(sampling["seconds"])} if "seconds" in sampling else {}
    return decision.marginals, timings, details


def problog_program(probabilities: np.ndarray) -> str:
    """The ProbLog model of the consistent worlds of ``probabilities``."""
    n = len(probabilities)
    ids = box_ids(n)
    pairs = [(i, j) for i in range(n) for j in range(n) if i != j]
    lines = [f"{float(probabilities[i, j])!r}::s({ids[i]},{ids[j]})." for i, j in pairs]
    lines += ["inconsistent :- s(X,Y), s(Y,Z), X \\= Z, \\+ s(X,Z).", "evidence(inconsistent, false)."]
    lines += [f"query(s({ids[i]},{ids[j]}))." for i, j in pairs]
    return "\n".join(lines) + "\n"


def run_problog(probabilities: np.ndarray) -> CallResult:
    from problog import get_evaluatable
    from problog.program import PrologString

    n = len(probabilities)
    index = {name: i for i, name in enumerate(box_ids(n))}
    start = time.perf_counter()
    formula = get_evaluatable().create_from(PrologString(problog_program(probabilities)))
    compiled = time.perf_counter()
    results = formula.evaluate()
    done = time.perf_counter()
    marginals = np.zeros((n, n))
    for term, value in results.items():
        x, y = (index[str(arg)] for arg in term.args)
        marginals[x, y] = value
    timings = {"ground": compiled - start, "compile+count": done - compiled}
    return marginals, timings, {"formula": type(formula).__name__, "queries": len(results)}


def run_pysdd(probabilities: np.ndarray, minimize: bool) -> CallResult:
    from itertools import permutations

    from pysdd.sdd import SddManager, Vtree

    n = len(probabilities)
    pairs = [(i, j) for i in range(n) for j in range(n) if i != j]
    variable = {pair: k + 1 for k, pair in enumerate(pairs)}
    start = time.perf_counter()
    manager = SddManager.from_vtree(Vtree(var_count=len(pairs), vtree_type="balanced"))
    if minimize:
        manager.auto_gc_and_minimize_on()
    constraint = manager.true()
    for x, y, z in permutations(range(n), 3):
        clause = manager.literal(-variable[x, y]) | manager.literal(-variable[y, z]) | manager.literal(variable[x, z])
        constraint = constraint & clause
    compiled = time.perf_counter()
    wmc = constraint.wmc(log_mode=True)
    for (x, y), var in variable.items():
        wmc.set_literal_weight(manager.literal(var), math.log(probabilities[x, y]))
        wmc.set_literal_weight(manager.literal(-var), math.log1p(-probabilities[x, y]))
    wmc.propagate()
    marginals = np.zeros((n, n))
    for (x, y), var in variable.items():
        marginals[x, y] = math.exp(wmc.literal_pr(manager.literal(var)))
    done = time.perf_counter()
    timings = {"compile": compiled - start, "count": done - compiled}
    details = {"sdd_size": int(constraint.size()), "vtree": "balanced", "minimize": minimize}
    return marginals, timings, details


class Underflow(ArithmeticError):
    """A weighted count that float64 cannot hold (0, subnormal or infinite)."""


def run_pyganak(probabilities: np.ndarray) -> CallResult:
    from itertools import permutations

    from pyganak import WeightedCounter

    n = len(probabilities)
    pairs = [(i, j) for i in range(n) for j in range(n) if i != j]
    variable = {pair: k + 1 for k, pair in enumerate(pairs)}
    clauses = [[-variable[x, y], -variable[y, z], variable[x, z]] for x, y, z in permutations(range(n), 3)]
    weights: list[tuple[int, float]] = []
    for (x, y), var in variable.items():
        p = float(probabilities[x, y])
        larger = max(p, 1.0 - p)  # rescale each pair: the likelier literal weighs 1
        weights += [(var, p / larger), (-var, (1.0 - p) / larger)]

    def count(unit: int | None = None) -> float:
        counter = WeightedCounter()  # count() may be called once per counter
        counter.add_clauses(clauses)
        if unit is not None:
            counter.add_clause([unit])
        for literal, weight in weights:
            counter.set_lit_weight(literal, weight)
        return float(counter.count())

    start = time.perf_counter()
    total = count()
    counted = time.perf_counter()
    if not (math.isfinite(total) and total >= sys.float_info.min):
        raise Underflow(f"Z = {total!r} (rescaled weights) is not a normal float64: the marginals would be garbage")
    marginals = np.zeros((n, n))
    for (x, y), var in variable.items():
        # Z_xy >= 0 and Z normal: a subnormal Z_xy costs at most 5e-324 / Z absolute error
        marginals[x, y] = count(var) / total
    done = time.perf_counter()
    timings = {"Z": counted - start, f"{len(pairs)} x Z_xy": done - counted}
    details = {"counts": len(pairs) + 1, "clauses": len(clauses), "z_rescaled": total}
    return marginals, timings, details


def worker(
    method: str,
    family: str,
    n: int,
    seed: int,
    max_boxes: int | None,
    sdd_minimize: bool,
    repeat: int,
    budget: float,
    approx_seconds: float = 1.0,
) -> Outcome:
    """Time ``method`` on one instance inside this process (the child)."""
    outcome = Outcome(method, family, n, seed)
    probabilities = instance(family, n, seed)
    start = time.perf_counter()
    call: Callable[[], CallResult]
    if method in ("exact", "exact-1t", "sat"):
        import unstack

        name = "sat" if method == "sat" else "exact"
        call = lambda: run_unstack(name, probabilities, max_boxes)  # noqa: E731
        outcome.details["unstack"] = unstack.__version__
    elif method == "approx":
        import unstack

        call = lambda: run_approx(probabilities, approx_seconds)  # noqa: E731
        outcome.details["unstack"] = unstack.__version__
        outcome.details["time_limit"] = approx_seconds
    elif method == "problog":
        import problog

        call = lambda: run_problog(probabilities)  # noqa: E731
        outcome.details["problog"] = problog.version.version
    elif method == "pysdd":
        from importlib.metadata import version

        import pysdd.sdd  # noqa: F401

        call = lambda: run_pysdd(probabilities, sdd_minimize)  # noqa: E731
        outcome.details["pysdd"] = version("PySDD")
    elif method == "pyganak":
        import pyganak

        call = lambda: run_pyganak(probabilities)  # noqa: E731
        outcome.details["pyganak"] = pyganak.__version__
    else:
        raise ValueError(f"unknown method {method!r}")
    outcome.import_seconds = time.perf_counter() - start
    outcome.details["loadavg_before"] = round(os.getloadavg()[0], 2)
    times: list[tuple[float, dict[str, float]]] = []
    marginals = np.zeros((n, n))
    spent = 0.0
    for index in range(1 + repeat):
        begin = time.perf_counter()
        marginals, timings, details = call()
        elapsed = time.perf_counter() - begin
        times.append((elapsed, timings))
        outcome.details.update(details)
        if index == 0:
            outcome.first_seconds = elapsed
            outcome.first_done_at = time.time()
        spent += elapsed
        if elapsed > REPEAT_BELOW_SECONDS or spent + elapsed > budget:
            break
    # the first call of unstack exact loads numba's cached code: warm figures exclude it
    warm = times[1:] if len(times) > 1 else times
    best, best_timings = min(warm, key=lambda item: item[0])
    outcome.seconds = best
    outcome.calls = len(times)
    outcome.phases = best_timings
    outcome.marginals = marginals.tolist()
    return outcome


def worker_main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(prog="peers.py --worker")
    parser.add_argument("--worker", required=True, choices=METHODS)
    parser.add_argument("--family", required=True, choices=ALL_FAMILIES)
    parser.add_argument("--n", type=int, required=True)
    parser.add_argument("--seed", type=int, required=True)
    parser.add_argument("--max-boxes", type=int, default=None)
    parser.add_argument("--sdd-minimize", action="store_true")
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--budget", type=float, default=60.0)
    parser.add_argument("--approx-seconds", type=float, default=1.0)
    parser.add_argument("--out", type=Path, required=True)
    args = parser.parse_args(argv)
    try:
        outcome = worker(
            args.worker,
            args.family,
            args.n,
            args.seed,
            args.max_boxes,
            args.sdd_minimize,
            args.repeat,
            args.budget,
            args.approx_seconds,
        )
    except Underflow as error:
        outcome = Outcome(args.worker, args.family, args.n, args.seed, status="underflow", reason=str(error))
    except MemoryError:
        outcome = Outcome(args.worker, args.family, args.n, args.seed, status="memory", reason="MemoryError")
    except ImportError as error:
        outcome = Outcome(args.worker, args.family, args.n, args.seed, status="error", reason=f"cannot import: {error}")
    except Exception as error:  # noqa: BLE001 -- any failure of a peer is a result to report
        outcome = Outcome(
            args.worker, args.family, args.n, args.seed, status="error", reason=f"{type(error).__name__}: {error}"
        )
    atomic_write_text(args.out, json.dumps(asdict(outcome)))
    return 0


# --------------------------------------------------------------------------- parent


def limit_memory(gib: float) -> Callable[[], None]:
    def apply() -> None:
        limit = int(gib * 2**30)
        resource.setrlimit(resource.RLIMIT_AS, (limit, limit))

    return apply


def run_child(method: str, family: str, n: int, seed: int, args: argparse.Namespace, out_dir: Path) -> Outcome:
    """Run one worker in a subprocess: timeout, memory limit, peak RSS via ``wait4``."""
    out = out_dir / f"{method}-{family}-{n}.json"
    command = [sys.executable, str(Path(__file__).resolve()), "--worker", method, "--family", family]
    command += ["--n", str(n), "--seed", str(seed), "--repeat", str(args.repeat), "--out", str(out)]
    command += ["--budget", str(args.timeout / 2), "--approx-seconds", str(args.approx_seconds)]
    if args.max_boxes is not None:
        command += ["--max-boxes", str(args.max_boxes)]
    if args.sdd_minimize:
        command.append("--sdd-minimize")
    env = dict(os.environ)
    if method == "exact-1t":
        env["NUMBA_NUM_THREADS"] = "1"
    stderr_file = out_dir / f"{method}-{family}-{n}.stderr"
    waited: dict[str, Any] = {}
    with open(stderr_file, "wb") as stderr:
        start = time.perf_counter()
        spawned_at = time.time()
        process = subprocess.Popen(
            command, stdout=subprocess.DEVNULL, stderr=stderr, env=env, preexec_fn=limit_memory(args.memory_limit_gib)
        )

        def wait() -> None:
            _, status, usage = os.wait4(process.pid, 0)
            waited["wall"] = time.perf_counter() - start
            waited["status"] = status
            waited["usage"] = usage

        waiter = threading.Thread(target=wait, daemon=True)
        waiter.start()
        waiter.join(args.timeout)
        timed_out = waiter.is_alive()
        if timed_out:
            process.kill()
            waiter.join()
        process.returncode = 0  # reaped by wait4; keep Popen from waiting again
    wall = waited["wall"]
    rss = waited["usage"].ru_maxrss / 1024  # Linux reports KiB
    if timed_out:
        outcome = Outcome(method, family, n, seed, status="timeout", reason=f"killed after {args.timeout:g} s")
    elif out.exists():
        data = json.loads(out.read_text())
        outcome = Outcome(**data)
    else:
        status = waited["status"]
        tail = stderr_file.read_text(errors="replace").strip().splitlines()[-1:] or [""]
        if os.WIFSIGNALED(status):
            signal_name = signal.Signals(os.WTERMSIG(status)).name
            outcome = Outcome(method, family, n, seed, status="error", reason=f"died by {signal_name}: {tail[0]}")
        else:
            outcome = Outcome(
                method, family, n, seed, status="error", reason=f"exit {os.WEXITSTATUS(status)}: {tail[0]}"
            )
        if "MemoryError" in tail[0] or "bad_alloc" in tail[0] or "memory" in tail[0].lower():
            outcome.status = "memory"
    outcome.wall_seconds = wall
    if outcome.first_done_at is not None:
        outcome.end_to_end_seconds = outcome.first_done_at - spawned_at
    outcome.max_rss_mib = rss
    return outcome


def parse_sizes(text: str) -> list[int]:
    """Box counts from ``3-8,10,20,40``: ranges and single sizes, sorted, each once.

    Examples
    --------
    >>> parse_sizes("10,3-5, 4,40")
    [3, 4, 5, 10, 40]
    """
    sizes: set[int] = set()
    for part in (piece.strip() for piece in text.split(",")):
        if not part:
            continue
        try:
            if "-" in part:
                low, high = (int(bound) for bound in part.split("-"))
                if low > high:
                    raise ValueError
                sizes.update(range(low, high + 1))
            else:
                sizes.add(int(part))
        except ValueError:
            raise argparse.ArgumentTypeError(f"bad size {part!r}: expected N or LOW-HIGH, e.g. 3-8,10,20") from None
    if not sizes or min(sizes) < 2:
        raise argparse.ArgumentTypeError(f"sizes {text!r}: need at least one size, each at least 2")
    return sorted(sizes)


def static_skip(method: str, family: str, n: int, seed: int, max_boxes: int | None) -> str | None:
    """Why ``method`` cannot run this instance at all (without trying), or None."""
    if method == "sat" and n > SAT_MAX_BOXES:
        return f"unstack sat refuses n > {SAT_MAX_BOXES}"
    limit = max_boxes or EXACT_MAX_BOXES
    if method in ("exact", "exact-1t") and n > limit:
        return f"unstack exact refuses n > {limit} (--max-boxes raises it)"
    try:
        instance(family, n, seed)
    except ValueError as error:
        return str(error)
    return None


def compare(outcomes: list[Outcome]) -> None:
    """Fill in differences and ratios against unstack exact of the same instance."""
    reference = {(o.family, o.n): o for o in outcomes if o.method == "exact" and o.status == "ok"}
    for outcome in outcomes:
        exact = reference.get((outcome.family, outcome.n))
        if exact is None or outcome.status != "ok":
            continue
        if outcome.marginals is not None and exact.marginals is not None:
            mine, theirs = np.array(outcome.marginals), np.array(exact.marginals)
            outcome.max_abs_diff = float(np.max(np.abs(mine - theirs)))
            outcome.max_ec_error = float(np.max(np.abs(mine.sum(axis=1) - theirs.sum(axis=1))))
            if outcome.method not in APPROXIMATE:
                outcome.agrees = outcome.max_abs_diff <= AGREE_TOLERANCE
        if outcome.seconds and exact.seconds:
            outcome.ratio = outcome.seconds / exact.seconds
        if outcome.end_to_end_seconds and exact.end_to_end_seconds:
            outcome.wall_ratio = outcome.end_to_end_seconds / exact.end_to_end_seconds


def ratio_text(value: float | None) -> str:
    if value is None:
        return ""
    return f"{value:.3g}x"


COLUMNS = (
    "n",
    "method",
    "compute",
    "ratio",
    "first call",
    "end to end",
    "e2e ratio",
    "phases",
    "peak RSS",
    "max abs diff",
    "max EC err",
    "status",
)


def row(outcome: Outcome) -> list[str]:
    ok = outcome.status == "ok"
    split = " + ".join(f"{name} {seconds_text(value)}" for name, value in outcome.phases.items()) if ok else ""
    diff = "" if outcome.max_abs_diff is None else f"{outcome.max_abs_diff:.1e}"
    ec_error = "" if outcome.max_ec_error is None else f"{outcome.max_ec_error:.1e}"
    if outcome.method == "exact" and ok:
        diff = ec_error = "(reference)"
    status = "ok" if ok else f"{outcome.status}: {outcome.reason}"
    if outcome.agrees is False:
        status = f"DISAGREES (> {AGREE_TOLERANCE:g})"
    elif outcome.method in APPROXIMATE and ok:
        status = "ok (estimate)"
        standard_error = outcome.details.get("max_ec_standard_error")
        if standard_error is not None:
            ec_error += f" (se {standard_error:.1e})" if ec_error else f"se {standard_error:.1e}"
        acceptance = outcome.details.get("acceptance")
        if acceptance:
            status += f", acceptance {min(acceptance):.2f}"
            if min(acceptance) < STUCK_ACCEPTANCE:
                status += " -- chains barely moved: errors unreliable"
    return [
        str(outcome.n),
        LABELS[outcome.method],
        seconds_text(outcome.seconds) if ok else "",
        ratio_text(outcome.ratio),
        seconds_text(outcome.first_seconds) if ok else "",
        seconds_text(outcome.end_to_end_seconds) if ok else "",
        ratio_text(outcome.wall_ratio),
        split,
        "" if outcome.max_rss_mib is None else f"{outcome.max_rss_mib:.0f} MiB",
        diff,
        ec_error,
        status,
    ]


def largest_within(outcomes: list[Outcome], timeout: float) -> dict[str, dict[str, dict[str, Any]]]:
    """Per family and method: the largest ``n`` that answered, and what stopped it."""
    summary: dict[str, dict[str, dict[str, Any]]] = {}
    for family in dict.fromkeys(o.family for o in outcomes):
        summary[family] = {}
        for method in dict.fromkeys(o.method for o in outcomes if o.family == family):
            mine = sorted((o for o in outcomes if o.family == family and o.method == method), key=lambda o: o.n)
            answered = [o.n for o in mine if o.status == "ok"]
            largest = max(answered) if answered else None
            stopped = next(
                (o for o in mine if o.status != "ok" and (largest is None or o.n > largest)),
                None,
            )
            entry: dict[str, Any] = {"largest_n": largest, "timeout": timeout}
            if stopped is not None:
                entry["stopped_at"] = stopped.n
                entry["stopped_by"] = f"{stopped.status}: {stopped.reason}"
            disagreeing = [o.n for o in mine if o.agrees is False]
            if disagreeing:
                entry["disagrees_at"] = disagreeing
            summary[family][method] = entry
    return summary


def summary_lines(summary: dict[str, dict[str, dict[str, Any]]]) -> list[str]:
    lines = []
    for family, methods in summary.items():
        for method, entry in methods.items():
            largest = "none" if entry["largest_n"] is None else str(entry["largest_n"])
            text = f"{family:<10} {LABELS[method]:<15} largest n within the {entry['timeout']:g} s timeout: {largest}"
            if "stopped_at" in entry:
                text += f" (n={entry['stopped_at']}: {entry['stopped_by']})"
            if "disagrees_at" in entry:
                text += f"; DISAGREES with exact at n={entry['disagrees_at']}"
            lines.append(text)
    return lines


def print_table(outcomes: list[Outcome], title: str) -> None:
    from rich.console import Console
    from rich.table import Table

    console = Console(width=None if sys.stdout.isatty() else 200)
    for family in dict.fromkeys(o.family for o in outcomes):
        table = Table(title=f"{title} -- {family}")
        for column in COLUMNS:
            table.add_column(column, justify="left" if column in ("method", "status") else "right")
        previous = None
        for outcome in (o for o in outcomes if o.family == family):
            if previous is not None and outcome.n != previous:
                table.add_section()
            previous = outcome.n
            table.add_row(*row(outcome))
        console.print(table)


def markdown(outcomes: list[Outcome]) -> str:
    text = []
    for family in dict.fromkeys(o.family for o in outcomes):
        text.append(f"**{family}**\n")
        text.append("| " + " | ".join(COLUMNS) + " |")
        text.append("|" + "|".join("---" if c in ("method", "status") else "---:" for c in COLUMNS) + "|")
        for outcome in (o for o in outcomes if o.family == family):
            text.append("| " + " | ".join(cell.replace("|", "\\|") for cell in row(outcome)) + " |")
        text.append("")
    return "\n".join(text)


def machine() -> dict[str, Any]:
    info: dict[str, Any] = {
        "python": platform.python_version(),
        "platform": platform.platform(),
        "cpus": os.cpu_count(),
    }
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                info["cpu"] = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return info


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if "--worker" in argv:
        return worker_main(argv)
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0] if __doc__ else None)
    parser.add_argument(
        "--sizes", type=parse_sizes, default="3-7", help="box counts, e.g. 3-7 or 3-8,10,20,40 (default 3-7)"
    )
    parser.add_argument(
        "--families", default=",".join(ALL_FAMILIES), help=f"comma-separated subset of {','.join(ALL_FAMILIES)}"
    )
    parser.add_argument("--methods", default=",".join(METHODS), help=f"comma-separated subset of {','.join(METHODS)}")
    parser.add_argument("--seed", type=int, default=0, help="instance seed (default 0)")
    parser.add_argument("--timeout", type=float, default=120.0, help="seconds per subprocess (default 120)")
    parser.add_argument("--memory-limit-gib", type=float, default=8.0, help="address-space limit per subprocess")
    parser.add_argument("--repeat", type=int, default=3, help="repeats after the first call (while < 20 s each)")
    parser.add_argument("--max-boxes", type=int, default=None, help="raise unstack exact's size limit (e.g. 9)")
    parser.add_argument("--sdd-minimize", action="store_true", help="PySDD: dynamic vtree minimization on")
    parser.add_argument(
        "--approx-seconds", type=float, default=1.0, help="approx: sampling time limit per call (default 1)"
    )
    parser.add_argument("--json", type=Path, default=None, help="write every outcome (with marginals) here")
    parser.add_argument("--markdown", type=Path, default=None, help="write the tables as Markdown here")
    args = parser.parse_args(argv)
    sizes: list[int] = args.sizes
    families = [f.strip() for f in args.families.split(",") if f.strip()]
    methods = [m.strip() for m in args.methods.split(",") if m.strip()]
    for name in families:
        if name not in ALL_FAMILIES:
            parser.error(f"unknown family {name!r}")
    for name in methods:
        if name not in METHODS:
            parser.error(f"unknown method {name!r}")
    if "exact" not in methods:
        methods.insert(0, "exact")  # the reference of every ratio and difference
    outcomes: list[Outcome] = []
    with tempfile.TemporaryDirectory(prefix="unstack-peers-") as tmp:
        for family in families:
            # an exact method that timed out (or ran out of memory) at n skips every larger n
            stopped: dict[str, Outcome] = {}
            for n in sizes:
                for method in methods:
                    reason = static_skip(method, family, n, args.seed, args.max_boxes)
                    if reason is None and method in stopped:
                        first = stopped[method]
                        reason = f"{first.status} at n={first.n}"
                        if first.status == "error":
                            reason = f"{first.reason} (n={first.n})"
                    if reason is not None:
                        outcome = Outcome(method, family, n, args.seed, status="skipped", reason=reason)
                    else:
                        outcome = run_child(method, family, n, args.seed, args, Path(tmp))
                        if outcome.status in ("timeout", "memory", "underflow") and method not in APPROXIMATE:
                            stopped[method] = outcome
                        elif outcome.status == "error" and outcome.reason.startswith("cannot import"):
                            stopped[method] = outcome  # not installed: the same at every size
                    outcomes.append(outcome)
                    shown = seconds_text(outcome.seconds) if outcome.status == "ok" else outcome.reason
                    print(f"{family} n={n} {method}: {outcome.status} {shown}", file=sys.stderr, flush=True)
    compare(outcomes)
    print_table(outcomes, f"P(S_xy | consistent), seed {args.seed}")
    summary = largest_within(outcomes, args.timeout)
    lines = summary_lines(summary)
    print("\n".join(lines))
    disagreeing = [o for o in outcomes if o.agrees is False]
    for outcome in disagreeing:
        print(
            f"DISAGREEMENT: {outcome.method} {outcome.family} n={outcome.n}: max abs diff "
            f"{outcome.max_abs_diff:.2e} > {AGREE_TOLERANCE:g}",
            file=sys.stderr,
        )
    if args.json is not None:
        arguments = vars(args) | {"json": str(args.json), "markdown": str(args.markdown)}
        report: dict[str, Any] = {"arguments": arguments}
        report["machine"] = machine()
        report["largest_n_within_timeout"] = summary
        report["outcomes"] = [asdict(o) for o in outcomes]
        atomic_write_text(args.json, json.dumps(report, indent=1))
    if args.markdown is not None:
        atomic_write_text(args.markdown, markdown(outcomes) + "\n" + "\n".join(f"- {line}" for line in lines) + "\n")
    return 1 if disagreeing else 0


if __name__ == "__main__":
    sys.exit(main())
