"""Side by side: unstack's two methods against ProbLog and PySDD on the same instances.

Every method answers the same question -- ``P(S_xy = 1 | consistent)`` for every ordered
pair -- on the matrices of :mod:`instances` (``dense`` and ``sparse``, seeded):

``exact``
    ``unstack.decide(supports, method="exact")``: weighted counting of preorders (numba,
    parallel over the machine's cores).
``exact-1t``
    the same with ``NUMBA_NUM_THREADS=1``: one core, like the peers.
``sat``
    ``unstack.decide(supports, method="sat")``: lists the worlds with CaDiCaL (n <= 6).
``problog``
    ProbLog 2 through its Python API with its default knowledge compiler (SDD when PySDD is
    installed): ``p::s(X,Y).`` per ordered pair, ``inconsistent :- s(X,Y), s(Y,Z), X \\= Z,
    \\+ s(X,Z).``, ``evidence(inconsistent, false).`` and ``query(s(X,Y)).`` per pair.
``pysdd``
    PySDD directly: the transitivity constraint (one clause ``-s_xy | -s_yz | s_xz`` per
    ordered triple) compiled bottom-up into an SDD over the ``n(n-1)`` pair variables, then
    one weighted model count with literal weights ``p`` and ``1 - p`` (log mode) and every
    conditional marginal from ``WmcManager.literal_pr`` after one ``propagate()``.

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

from instances import FAMILIES, box_ids, instance  # noqa: E402

METHODS: tuple[str, ...] = ("exact", "exact-1t", "sat", "problog", "pysdd")
LABELS: dict[str, str] = {
    "exact": "exact",
    "exact-1t": "exact 1 thread",
    "sat": "sat",
    "problog": "ProbLog",
    "pysdd": "PySDD",
}
#: unstack's SAT enumeration refuses more boxes than this.
SAT_MAX_BOXES = 6
#: Repeat a call only while one call takes less than this (seconds).
REPEAT_BELOW_SECONDS = 20.0


@dataclass
class Outcome:
    """One method on one instance."""

    method: str
    family: str
    n: int
    seed: int
    status: str = "ok"  # ok | timeout | memory | error | skipped
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
    ratio: float | None = None
    wall_ratio: float | None = None
    details: dict[str, Any] = field(default_factory=dict)
    marginals: list[list[float]] | None = None


# --------------------------------------------------------------------------- workers
# Each returns (marginals, timings, details) for one call on one matrix.

CallResult = tuple[np.ndarray, dict[str, float], dict[str, Any]]


def run_unstack(method: str, probabilities: np.ndarray, max_boxes: int | None) -> CallResult:
    import unstack

    supports = unstack.Supports(box_ids(len(probabilities)), probabilities)
    decision = unstack.decide(supports, method=method, max_boxes=max_boxes)
    return decision.marginals, {}, {"consistent_worlds": decision.consistent_worlds, "choice": decision.choice}


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


def worker(
    method: str, family: str, n: int, seed: int, max_boxes: int | None, sdd_minimize: bool, repeat: int, budget: float
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
    elif method == "problog":
        import problog

        call = lambda: run_problog(probabilities)  # noqa: E731
        outcome.details["problog"] = problog.version.version
    elif method == "pysdd":
        from importlib.metadata import version

        import pysdd.sdd  # noqa: F401

        call = lambda: run_pysdd(probabilities, sdd_minimize)  # noqa: E731
        outcome.details["pysdd"] = version("PySDD")
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
    parser.add_argument("--family", required=True, choices=FAMILIES)
    parser.add_argument("--n", type=int, required=True)
    parser.add_argument("--seed", type=int, required=True)
    parser.add_argument("--max-boxes", type=int, default=None)
    parser.add_argument("--sdd-minimize", action="store_true")
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--budget", type=float, default=60.0)
    parser.add_argument("--out", type=Path, required=True)
    args = parser.parse_args(argv)
    try:
        outcome = worker(
            args.worker, args.family, args.n, args.seed, args.max_boxes, args.sdd_minimize, args.repeat, args.budget
        )
    except MemoryError:
        outcome = Outcome(args.worker, args.family, args.n, args.seed, status="memory", reason="MemoryError")
    except ImportError as error:
        outcome = Outcome(args.worker, args.family, args.n, args.seed, status="error", reason=f"cannot import: {error}")
    except Exception as error:  # noqa: BLE001 -- any failure of a peer is a result to report
        outcome = Outcome(
            args.worker, args.family, args.n, args.seed, status="error", reason=f"{type(error).__name__}: {error}"
        )
    args.out.write_text(json.dumps(asdict(outcome)))
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
    command += ["--budget", str(args.timeout / 2)]
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
    sizes: list[int] = []
    for part in text.split(","):
        if "-" in part:
            low, high = part.split("-")
            sizes.extend(range(int(low), int(high) + 1))
        else:
            sizes.append(int(part))
    return sizes


def compare(outcomes: list[Outcome]) -> None:
    """Fill in differences and ratios against unstack exact of the same instance."""
    reference = {(o.family, o.n): o for o in outcomes if o.method == "exact" and o.status == "ok"}
    for outcome in outcomes:
        exact = reference.get((outcome.family, outcome.n))
        if exact is None or outcome.status != "ok":
            continue
        if outcome.marginals is not None and exact.marginals is not None:
            outcome.max_abs_diff = float(np.max(np.abs(np.array(outcome.marginals) - np.array(exact.marginals))))
        if outcome.seconds and exact.seconds:
            outcome.ratio = outcome.seconds / exact.seconds
        if outcome.end_to_end_seconds and exact.end_to_end_seconds:
            outcome.wall_ratio = outcome.end_to_end_seconds / exact.end_to_end_seconds


def seconds_text(value: float | None) -> str:
    if value is None:
        return ""
    if value < 0.01:
        return f"{value * 1000:.2f} ms"
    if value < 1:
        return f"{value * 1000:.0f} ms"
    return f"{value:.2f} s"


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
    "status",
)


def row(outcome: Outcome) -> list[str]:
    ok = outcome.status == "ok"
    split = " + ".join(f"{name} {seconds_text(value)}" for name, value in outcome.phases.items()) if ok else ""
    diff = "" if outcome.max_abs_diff is None else f"{outcome.max_abs_diff:.1e}"
    if outcome.method == "exact" and ok:
        diff = "(reference)"
    status = "ok" if ok else f"{outcome.status}: {outcome.reason}"
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
        status,
    ]


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
    parser.add_argument("--sizes", default="3-7", help="box counts, e.g. 3-7 or 3,5,8 (default 3-7)")
    parser.add_argument("--families", default=",".join(FAMILIES), help="comma-separated: dense,sparse")
    parser.add_argument("--methods", default=",".join(METHODS), help=f"comma-separated subset of {','.join(METHODS)}")
    parser.add_argument("--seed", type=int, default=0, help="instance seed (default 0)")
    parser.add_argument("--timeout", type=float, default=120.0, help="seconds per subprocess (default 120)")
    parser.add_argument("--memory-limit-gib", type=float, default=8.0, help="address-space limit per subprocess")
    parser.add_argument("--repeat", type=int, default=3, help="repeats after the first call (while < 20 s each)")
    parser.add_argument("--max-boxes", type=int, default=None, help="raise unstack exact's size limit (e.g. 9)")
    parser.add_argument("--sdd-minimize", action="store_true", help="PySDD: dynamic vtree minimization on")
    parser.add_argument("--json", type=Path, default=None, help="write every outcome (with marginals) here")
    parser.add_argument("--markdown", type=Path, default=None, help="write the tables as Markdown here")
    args = parser.parse_args(argv)
    sizes = parse_sizes(args.sizes)
    families = [f for f in args.families.split(",") if f]
    methods = [m for m in args.methods.split(",") if m]
    for name in families:
        if name not in FAMILIES:
            parser.error(f"unknown family {name!r}")
    for name in methods:
        if name not in METHODS:
            parser.error(f"unknown method {name!r}")
    if "exact" not in methods:
        methods.insert(0, "exact")  # the reference of every ratio and difference
    outcomes: list[Outcome] = []
    with tempfile.TemporaryDirectory(prefix="unstack-peers-") as tmp:
        for family in families:
            for n in sizes:
                for method in methods:
                    if method == "sat" and n > SAT_MAX_BOXES:
                        outcome = Outcome(method, family, n, args.seed, status="skipped")
                        outcome.reason = f"unstack sat refuses n > {SAT_MAX_BOXES}"
                    else:
                        outcome = run_child(method, family, n, args.seed, args, Path(tmp))
                    outcomes.append(outcome)
                    shown = seconds_text(outcome.seconds) if outcome.status == "ok" else outcome.reason
                    print(f"{family} n={n} {method}: {outcome.status} {shown}", file=sys.stderr, flush=True)
    compare(outcomes)
    print_table(outcomes, f"P(S_xy | consistent), seed {args.seed}")
    if args.json is not None:
        report = {"arguments": vars(args) | {"json": str(args.json), "markdown": str(args.markdown)}}
        report["machine"] = machine()
        report["outcomes"] = [asdict(o) for o in outcomes]
        args.json.write_text(json.dumps(report, indent=1))
    if args.markdown is not None:
        args.markdown.write_text(markdown(outcomes))
    return 0


if __name__ == "__main__":
    sys.exit(main())
