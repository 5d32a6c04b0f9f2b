"""``unstack`` commands: ``decide``, ``plan``, ``worlds``, ``validate``, ``warm-up``, and (loaded
on first use) ``simulate``, ``render``, ``view``, ``train``, ``evaluate``, ``probabilities``, ``experiment``.

Each command is a thin layer over the library: read the input, call one public function
(``unstack.decide``, ``unstack.plan``, ``unstack.validate``, ...), render the result.
``UnstackError`` (and unwritable outputs) become a single ``unstack: error: ...`` line on
stderr with exit code 2. Only what a command needs is imported: deciding on a supports
file loads neither scikit-learn, numba for small groups, networkx nor rich's tables.
"""

from __future__ import annotations

import contextlib
import functools
import importlib
import logging
import os
import re
import signal
import sys
import threading
import time
from collections.abc import Callable, Iterator
from typing import Any

import click

from unstack.cli.options import Checked
from unstack.cli.text import printable, shortened
from unstack.errors import InvalidArgument, UnstackError
from unstack.reasoner.arguments import check_budget, check_margin, check_samples, check_seed
from unstack.reasoner.costs import PAYOFF_COSTS

__all__ = ["cli", "main"]

MODEL_HELP = (
    "Model file, or a shipped model: general (the default: pose features, five pile families), paper (the "
    "paper's SVM, for the reproduction) or extended (the paper's piles with contact features)."
)
#: ``--model`` of every command that reads scenes through a model (the library's ``model_path``).
model_path_option = click.option("--model", "model_path", default=None, help=MODEL_HELP)
#: ``--model`` of the commands that hand it to :mod:`unstack.api` as ``model``.
model_option = click.option("--model", "model", default=None, help=MODEL_HELP)
#: The folder of a simulated data set (``unstack simulate --out``).
data_dir_argument = click.argument("data_dir", type=click.Path(file_okay=False))


def out_folder_option(help_text: str) -> Callable[[Callable[..., Any]], Callable[..., Any]]:
    """``--out``, the folder an experiment writes its results into; ``help_text`` names them.

    Checked when the command line is read (a file there, or above it, is refused before any
    work); a folder the run makes is removed again when the run fails with nothing in it.
    """
    return click.option("--out", required=True, type=click.Path(), help=help_text, callback=_new_results_folder)


def _new_results_folder(ctx: click.Context, _: click.Parameter, value: str) -> str:
    from unstack.atomic import check_folder_path

    folder = check_folder_path(value)
    if not folder.exists():
        ctx.meta.setdefault(_NEW_FOLDERS, []).append(folder)
    return value


def _remove_empty_new_folders(ctx: click.Context) -> None:
    """Remove the results folders this run made when it failed before writing a file in them."""
    for folder in ctx.meta.pop(_NEW_FOLDERS, []):
        if folder.is_dir() and not any(path.is_file() for path in folder.rglob("*")):
            for inner in sorted((path for path in folder.rglob("*") if path.is_dir()), reverse=True):
                inner.rmdir()
            folder.rmdir()


#: ``ctx.meta`` key of the results folders a run made.
_NEW_FOLDERS = "unstack.new_results_folders"


STATICS_HELP = (
    "For a scene: a box that cannot stand without another (leaning on it, or across a gap on it) makes that "
    "one its supporter (P raised to at least 0.65, with a warning); --no-statics keeps the model's probabilities."
)

#: Commands whose modules load only when they run (their imports are heavy).
LAZY_COMMANDS = {
    "simulate": "unstack.cli.simulation:simulate",
    "render": "unstack.cli.pictures:render",
    "view": "unstack.cli.pictures:view",
    "train": "unstack.cli.learning:train",
    "evaluate": "unstack.cli.learning:evaluate",
    "probabilities": "unstack.cli.learning:probabilities",
    "experiment": "unstack.cli.experiments:experiment",
    "scene": "unstack.cli.camera:scene",
}


#: The warnings said in this run of a command (emptied by :func:`main`).
_WARNED: set[str] = set()


def _fail(message: str) -> None:
    click.echo(f"unstack: error: {printable(shortened(message))}", err=True)
    sys.exit(2)


def _warn(message: str) -> None:
    """One line on stderr; a warning said already in this run (the scene's, then the decision's
    that repeats it) is not said again."""
    if message not in _WARNED:
        _WARNED.add(message)
        click.echo(f"unstack: warning: {printable(shortened(message))}", err=True)


class _Group(click.Group):
    """A click group that loads heavy commands lazily and turns library errors into one line."""

    def list_commands(self, ctx: click.Context) -> list[str]:
        return sorted([*super().list_commands(ctx), *LAZY_COMMANDS])

    def get_command(self, ctx: click.Context, cmd_name: str) -> click.Command | None:
        if cmd_name in LAZY_COMMANDS and cmd_name not in self.commands:
            module, name = LAZY_COMMANDS[cmd_name].split(":")
            command = getattr(importlib.import_module(module), name)
            self.add_command(command, cmd_name)
        return super().get_command(ctx, cmd_name)

    def invoke(self, ctx: click.Context) -> Any:
        try:
            return super().invoke(ctx)
        except BrokenPipeError:  # the reader stopped (| head): quiet, as other tools are
            _quiet_broken_pipe()
        except UnstackError as error:
            _remove_empty_new_folders(ctx)
            command = self.get_command(ctx, ctx.invoked_subcommand) if ctx.invoked_subcommand else None
            if isinstance(error, InvalidArgument) and command is not None:
                _fail(_option_names(str(error), command))
            _fail(str(error))
        except OSError as error:
            _remove_empty_new_folders(ctx)
            _fail(f"{getattr(error, 'filename', None) or ''}: {error.strerror or error}".lstrip(": "))
        return None


def _check_output(path: str | None, source: str) -> None:
    """Fail before any work when ``--output`` cannot be written (naming the user's path) or
    would replace the input file ``source``."""
    if path is not None:
        from unstack.atomic import check_output_path

        check_output_path(path, inputs=[source])


def _deliver(
    document: dict[str, Any], output: str | None, as_json: bool, view: str, *shown: Any, warnings: tuple[str, ...] = ()
) -> None:
    """Write ``--output``, print the warnings, then the JSON or the view of :mod:`unstack.cli.render` named ``view``.

    The JSON is indented unless that would make it larger than unstack reads back
    (:func:`unstack.jsonio.document_text`). The view's module (rich tables) is imported only when
    the view is printed.
    """
    from unstack.jsonio import document_text

    text = document_text(document, output or "--json") if output is not None or as_json else ""
    if output is not None:
        from unstack.atomic import atomic_write_text

        atomic_write_text(output, text)
    _print_warnings(warnings)
    if as_json:
        click.echo(text, nl=False)
        return
    from rich.console import Console

    from unstack.cli import render as views

    Console(highlight=False).print(getattr(views, view)(*shown))


def _load_input(path: str, model: str | None, statics: bool = True) -> Any:
    """A scene or supports file; ``--model`` and ``--no-statics`` only mean something for a scene."""
    import unstack

    loaded = unstack.load(path)
    if isinstance(loaded, unstack.Supports):
        for given, option in ((model is not None, "--model"), (not statics, "--no-statics")):
            if given:
                raise UnstackError(
                    f"{loaded.source}: {option} applies to a scene file; this file holds support probabilities already"
                )
    return loaded


#: Option types checked by the library's own argument checks (:mod:`unstack.cli.options`).
SECONDS = Checked(float, functools.partial(check_budget, name="time_limit"))
MARGIN = Checked(float, functools.partial(check_margin, name="near_tie_margin"))
FREE_COST = Checked(float, functools.partial(check_margin, name="free_cost"))
SAMPLES = Checked(int, check_samples)
SEED = Checked(int, check_seed)


def load_model_option(model: str | None) -> tuple[Any, str]:
    """The model of ``--model`` (a shipped model's name or a file; the default when None) and its name."""
    from unstack.api import load_model, model_label

    loaded = load_model(model)
    return loaded, model_label(loaded)


#: ``--free-cost`` of ``decide`` and ``plan`` (a scene's rule; support probabilities refuse it).
FREE_COST_OPTION = click.option(
    "--free-cost",
    "free_cost",
    type=FREE_COST,
    default=None,
    help="For a scene: the highest box whose expected cost is below this holds nothing up and is taken "
    "(default 0.5; 0 with --near-ties 0; 0: the reasoner's choice).",
)


def _reasoning_options(*, plan: bool) -> Callable[[Callable[..., Any]], Callable[..., Any]]:
    """The options shared by ``decide`` and ``plan``: method, cost, sampling budget, seed; their
    help says what they do in the one command or the other."""

    def add(command: Callable[..., Any]) -> Callable[..., Any]:
        return _add_reasoning_options(command, plan=plan)

    return add


def _default_samples_text() -> str:
    """The sampler's default budget by group size, in words (from the sampler itself)."""
    from itertools import groupby

    from unstack.reasoner.sampling import WIDE_SAMPLES, default_samples

    sizes = [(n, default_samples(n)) for n in range(2, 65)]
    spans = []
    for budget, group in groupby(sizes, key=lambda row: row[1]):
        members = [n for n, _ in group]
        first, last = members[0], members[-1]
        spans.append(f"{budget} for {first}+" if budget == WIDE_SAMPLES else f"{budget} for {first}-{last}")
    return ", ".join(spans) + " boxes"


def _add_reasoning_options(command: Callable[..., Any], *, plan: bool) -> Callable[..., Any]:
    from unstack.reasoner.costs import COSTS, DEFAULT_COST
    from unstack.reasoner.decision import METHODS
    from unstack.reasoner.marginals import EXACT_MAX_BOXES
    from unstack.reasoner.plan import PLAN_EXACT_MAX_BOXES, PLAN_SAMPLES

    moves = (
        ""
        if plan
        else "; moves (a scene): the boxes taking the box out is expected to move, from the learned disturbance model"
    )
    samples = (
        f"Recorded sweeps per sampled group at each step (default {PLAN_SAMPLES}, the chains starting from the "
        "previous step's; reproducible with --seed)."
        if plan
        else f"Recorded sweeps per sampled group (default {_default_samples_text()}; reproducible with --seed)."
    )
    seconds = "each step" if plan else "the whole decision"

    options = [
        click.option(
            "--method",
            type=click.Choice(list(METHODS)),
            default="auto",
            show_default=True,
            help="exact: weighted preorder counting (<= 8 boxes per group); sat: list worlds with CaDiCaL "
            "(<= 6); approx: sampling with standard errors (any size); auto: per group, exact up to "
            f"{PLAN_EXACT_MAX_BOXES if plan else EXACT_MAX_BOXES}, else approx.",
        ),
        click.option(
            "--cost",
            type=click.Choice([*COSTS] if plan else [*COSTS, "moves"]),
            default=DEFAULT_COST,
            show_default=True,
            help="load: supported boxes, each with the undetected load on it; count: number of supported "
            f"boxes (Eq. 11); mass: their total mass (needs masses){moves}.",
        ),
        click.option(
            "--samples",
            type=SAMPLES,
            default=None,
            help=samples,
        ),
        click.option(
            "--time-limit",
            type=SECONDS,
            default=None,
            help=f"Seconds for {seconds} (not reproducible; with --samples, whichever ends first; under 10 "
            "also samples groups of 8).",
        ),
        click.option("--seed", type=SEED, default=None, help="Seed of the sampler."),
        click.option(
            "--near-ties",
            "near_tie_margin",
            type=MARGIN,
            default=None,
            help="Expected costs within this many boxes of the lowest are tied and the box resting highest is taken; "
            "on one layer the lowest cost (default 0.05 for a scene or supports with heights; 0: the minimum EC, "
            "Eq. 12).",
        ),
    ]
    for option in reversed(options):
        command = option(command)
    return command


@contextlib.contextmanager
def _first_call(loaded: Any) -> Iterator[None]:
    """Say at once when numba starts compiling kernels inside the block; a spinner on a terminal meanwhile."""
    import unstack
    from unstack.warmup import might_compile

    boxes = len(loaded.detected) if isinstance(loaded, unstack.Scene) else len(loaded.objects)
    if not (isinstance(loaded, unstack.Scene) or might_compile(boxes)):
        yield  # plain Python: numba is not even imported
        return
    from unstack.warmup import announcing_compilation

    with contextlib.ExitStack() as stack:

        def announce(sentence: str) -> None:
            click.echo(f"unstack: note: {sentence}", err=True)
            if sys.stderr.isatty():
                from rich.console import Console

                stack.enter_context(Console(stderr=True).status("compiling numba's kernels ..."))

        with announcing_compilation(announce):
            yield


def _option_names(message: str, command: click.Command) -> str:
    """A library argument error in the command line's words: the keyword arguments that are
    options of ``command`` by another name (``near_tie_margin``: ``--near-ties``) named as options.
    Only names with an underscore: a plain word (``model``, ``samples``) is left as it is.

    Examples
    --------
    >>> from unstack.cli.main import decide
    >>> _option_names("p.json: free_cost takes the highest box by its centre", decide)
    'p.json: --free-cost takes the highest box by its centre'
    """
    for parameter in command.params:
        if isinstance(parameter, click.Option) and parameter.name and "_" in parameter.name:
            option = max(parameter.opts, key=len)  # the long form
            message = re.sub(rf"\b{parameter.name}\b", option, message)
    return message


#: A run the command line announces up front when its budget allows longer (seconds).
LONG_RUN = 60.0


def _duration(seconds: float) -> str:
    """``seconds`` in the largest unit that keeps it readable (``2.5 h``)."""
    for unit, size in (("days", 86_400.0), ("h", 3_600.0), ("min", 60.0)):
        if seconds >= size:
            return f"{seconds / size:,.1f} {unit}"
    return f"{seconds:.0f} s"


#: A library warning's argument, as the command's option says it (``samples=4096`` -> ``--samples 4096``).
_ARGUMENT = re.compile(r"\b(samples|seed|time_limit)=([^\s);,]+)")


def _print_warnings(warnings: tuple[str, ...]) -> None:
    """The library's warnings as the command's lines, its arguments named as the options are."""
    for warning in warnings:
        _warn(_ARGUMENT.sub(lambda found: f"--{found[1].replace('_', '-')} {found[2]}", warning))


@click.group(cls=_Group, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(package_name="unstack")
def cli() -> None:
    """Decide which carton box to unload first from support probabilities."""


@cli.command()
@click.argument("file", type=str)
@click.option("--json", "as_json", is_flag=True, help="Print the decision as unstack.decision/1 JSON.")
@click.option(
    "-o", "--output", type=click.Path(dir_okay=False), help="Also write the JSON decision to this file (atomically)."
)
@click.option("--timing", is_flag=True, help="Add wall-clock seconds to the JSON (it is canonical without them).")
@_reasoning_options(plan=False)
@FREE_COST_OPTION
@click.option(
    "--physics-veto", is_flag=True,
    help="For a scene, with the physics engine (unstack[sim]): try the pick in belief worlds built from the scene "
    "and, where it is expected to move a box, take the box holding nothing up expected to move the fewest "
    "(0.3-2 s on simulated piles of 5-40 boxes; not applied where the scene's poses cannot stand).",
)  # fmt: skip
@model_option
@click.option("--statics/--no-statics", default=True, show_default=True, help=STATICS_HELP)
def decide(file: str, as_json: bool, output: str | None, timing: bool, model: str | None, **reasoning: Any) -> None:
    """Print which box to unload first, the expected cost of every box and P(support | consistent).

    FILE is an unstack.supports/1 file, or an unstack.scene/1 file whose detected boxes get
    their support probabilities from the learned model ('-' reads standard input).
    Groups of linked boxes too large to count are sampled: each EC then has a standard
    error, and the headline says how probable it is that the choice is truly the minimum.
    """
    import unstack

    _check_output(output, file)
    loaded = _load_input(file, model, reasoning["statics"])
    from unstack.cli.progress import still_working

    with _first_call(loaded), still_working("deciding"):
        decision = unstack.decide(loaded, model=model, **reasoning)
    cloud = isinstance(loaded, unstack.Scene)  # the undetected load from a point cloud, or from the file
    _deliver(
        decision.to_dict(timing=timing), output, as_json, "decision_view", decision, cloud, warnings=decision.warnings
    )


@cli.command()
@click.argument("file", type=str)
@click.option("--json", "as_json", is_flag=True, help="Print every world as JSON (unstack.payoff/1).")
@click.option("-o", "--output", type=click.Path(dir_okay=False), help="Also write the JSON payoff matrix to this file.")
@click.option("--limit", type=click.IntRange(min=1), default=20, show_default=True, help="Worlds shown in the table.")
@click.option(
    "--cost",
    type=click.Choice(list(PAYOFF_COSTS)),
    default="count",
    show_default=True,
    help="count: the boxes each action brings down in each world (Eq. 11); mass: their mass (needs "
    "masses). decide's default load cost, which adds the undetected load, is not listed world by world.",
)
@model_option
def worlds(file: str, as_json: bool, output: str | None, limit: int, cost: str, model: str | None) -> None:
    """Print the payoff matrix (Table II): consistent worlds, their probabilities and action costs.

    Lists worlds with a SAT solver, so it is for small scenes (up to 6 boxes).
    """
    from unstack.api import payoff

    _check_output(output, file)
    from unstack.cli.progress import still_working

    loaded = _load_input(file, model)
    with still_working("listing the worlds"):
        table = payoff(loaded, model, cost=cost)
    _deliver(table.to_dict(), output, as_json, "payoff_view", table, limit, warnings=table.warnings)


@cli.command()
@click.argument("file", type=str)
@click.option("--json", "as_json", is_flag=True, help="Print the plan as unstack.plan/1 JSON.")
@click.option("-o", "--output", type=click.Path(dir_okay=False), help="Also write the JSON plan to this file.")
@_reasoning_options(plan=True)
@FREE_COST_OPTION
@model_option
@click.option("--statics/--no-statics", default=True, show_default=True, help=STATICS_HELP)
def plan(file: str, as_json: bool, output: str | None, model: str | None, **reasoning: Any) -> None:
    """Order all detected boxes by repeated decisions: pick, remove from the set, decide again.

    With sampling, the budget (--samples or --time-limit) applies to each step; without one
    each step samples 2048 sweeps per group, starting from the previous step's chains, so a
    seed reproduces the plan. A progress bar on a terminal counts the steps (in a pipe or a log, a
    line every 30 s of a long plan).
    """
    import unstack
    from unstack.cli.progress import progress_bar

    _check_output(output, file)
    supports = _load_input(file, model, reasoning["statics"])
    steps = len(supports.detected if isinstance(supports, unstack.Scene) else supports.objects)
    if reasoning["time_limit"] is not None and steps * reasoning["time_limit"] > LONG_RUN:
        click.echo(
            f"unstack: note: --time-limit applies to each of the {steps} steps: the plan may sample for "
            f"{_duration(steps * reasoning['time_limit'])} in all",
            err=True,
        )
    with _first_call(supports), progress_bar("planning: steps") as report:
        report(0, steps)  # the count is known before the first step ends
        result = unstack.plan(supports, model=model, progress=report, **reasoning)
    cloud = isinstance(supports, unstack.Scene)  # the undetected load from a point cloud, or from the file
    _deliver(result.to_dict(), output, as_json, "plan_view", result, cloud, warnings=result.warnings)


@cli.command()
@click.argument("files", nargs=-1, required=True, type=str)
def validate(files: tuple[str, ...]) -> None:
    """Check every file against its schema and what a schema cannot say (ids, matrices, hard evidence).

    One line per file (valid on stdout, invalid on stderr), then a summary; exit code 2 when
    any file is invalid.
    """
    import unstack

    if files.count("-") > 1:
        raise UnstackError("-: standard input can be read once; it is named twice")
    invalid = 0
    for file in files:
        try:
            result = unstack.validate(file)
        except UnstackError as error:
            invalid += 1
            click.echo(f"unstack: error: {printable(str(error))}", err=True)
            continue
        click.echo(f"{printable(result.source)}: valid {result.format} ({printable(result.detail)})")
        _print_warnings(result.warnings)
    valid = len(files) - invalid
    click.echo(f"{len(files)} file{'s' if len(files) != 1 else ''}: {valid} valid, {invalid} invalid")
    if invalid:
        sys.exit(2)


@cli.command("warm-up")
@click.option(
    "--jobs",
    type=click.IntRange(min=1),
    default=None,
    help="Processes compiling at once (default: the cores, at most one per group of kernels).",
)
def warm_up(jobs: int | None) -> None:
    """Compile numba's kernels now (once after installing; later runs load them from the cache).

    The first decision on six or more linked boxes, the first sampled group and the first
    scene otherwise pay this compilation themselves. Each group compiles on one core, so
    several processes share the wait.
    """
    from unstack.warmup import KERNELS
    from unstack.warmup import warm_up as compile_kernels

    total = len(KERNELS)
    jobs = min(total, jobs) if jobs is not None else max(1, min(total, os.cpu_count() or 1))  # one a group at most
    done = [0]
    start = time.perf_counter()
    click.echo(
        f"warm-up: compiling {total} groups of kernels in {jobs} process{'es' if jobs > 1 else ''} "
        "(a minute or more after a fresh install) ...",
        err=True,
    )

    def report(name: str, seconds: float) -> None:
        done[0] += 1
        click.echo(f"warm-up: [{done[0]}/{total}] {name} ready in {seconds:.1f} s", err=True)

    compile_kernels(report, jobs=jobs)
    click.echo(f"warm-up: done in {time.perf_counter() - start:.1f} s; numba's cache holds the kernels")


def _warning_line(message: Warning | str, category: type[Warning], *_: object, **__: object) -> None:
    """Library warnings (an empty point cloud, say) as one line on stderr, without source lines;
    a message said once (a data set checked by the command and again by the library it calls)."""
    _warn(str(message))


#: matplotlib's words when it cannot write its folder: the folder it took instead, and why.
_TEMPORARY_FOLDER = re.compile(
    r"created a temporary \S* ?directory at (?P<folder>\S+) because there was an issue with (?P<issue>.+?);"
)


class _LibraryLogLines(logging.Handler):
    """The warnings a library logs (matplotlib, when no folder of its own is writable) as one
    ``unstack: warning:`` line each, instead of the logging module's bare lines on stderr."""

    def emit(self, record: logging.LogRecord) -> None:
        message = record.getMessage()
        if message.startswith("mkdir -p failed") or message.endswith("is not a writable directory"):
            return  # said again by the next record, with the folder taken instead
        found = _TEMPORARY_FOLDER.search(message)
        if found:
            message = (
                f"{found['issue']} is not a writable folder; its cache is kept in {found['folder']} for this run "
                "only (set MPLCONFIGDIR to a writable folder)"
            )
        _warn(f"{record.name.split('.')[0]}: {message}")


def _quiet_broken_pipe() -> None:
    """Leave quietly with exit code 1 when the reader of standard output has gone (Python's recipe:
    standard output is pointed at the null device, so the flush at exit raises nothing)."""
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, sys.stdout.fileno())
    sys.exit(1)


#: The exit code of a run stopped with Ctrl-C (128 + SIGINT, as the shell reports it).
INTERRUPTED = 130
#: The exit code of a run ended by SIGTERM (the shell's 128 + 15).
TERMINATED = 143


class _Terminated(KeyboardInterrupt):
    """SIGTERM, unwound as Ctrl-C is: worker pools shut down, temporary files removed."""


def _terminate(signum: int, frame: Any) -> None:
    raise _Terminated


def _check_numba_environment() -> None:
    """Refuse numba settings the reasoner cannot run with, before any work (numba's own words
    are a traceback, or a warning with one inside)."""
    threads = os.environ.get("NUMBA_NUM_THREADS")
    if threads is not None and not (threads.strip().isdigit() and int(threads) >= 1):
        _fail(f"NUMBA_NUM_THREADS: expected a whole number of at least 1, got {threads!r}")
    if os.environ.get("NUMBA_DISABLE_JIT", "0").strip() not in ("", "0"):
        _fail("NUMBA_DISABLE_JIT is set: the reasoner's kernels need numba's compiler; unset it")


#: The narrowest terminal the tables are drawn for: a narrower COLUMNS (0 printed nothing at all,
#: 20 only "…" in every cell) is taken as this many.
MIN_COLUMNS = 60


def main() -> None:
    """Console-script entry point."""
    import warnings

    warnings.showwarning = _warning_line
    library_log = logging.getLogger("matplotlib")
    if not any(isinstance(handler, _LibraryLogLines) for handler in library_log.handlers):
        library_log.addHandler(_LibraryLogLines(logging.WARNING))
        library_log.propagate = False
    _WARNED.clear()  # once per run of the command, also when it is run again in one process
    if sys.stdout is None:  # started with standard output closed (>&-): every result would be lost
        _fail("standard output is closed: nothing could be printed; redirect it to a file or to /dev/null")
    _check_numba_environment()
    if threading.current_thread() is threading.main_thread():  # a SIGTERM unwinds as Ctrl-C does
        signal.signal(signal.SIGTERM, _terminate)
    columns = os.environ.get("COLUMNS", "")
    if columns and not (columns.isdigit() and int(columns) >= MIN_COLUMNS):  # 0 printed nothing, 20 only "…"
        os.environ["COLUMNS"] = str(MIN_COLUMNS)
    for stream in (sys.stdout, sys.stderr):  # an ascii terminal (PYTHONIOENCODING=ascii) shows 'é' as \xe9
        if stream is not None and hasattr(stream, "reconfigure"):
            stream.reconfigure(errors="backslashreplace")
    try:
        status = cli.main(prog_name="unstack", standalone_mode=False)
    except click.exceptions.NoArgsIsHelpError as error:  # bare "unstack": the help, as click shows it
        click.echo(error.format_message(), err=True)
        sys.exit(2)
    except click.UsageError as error:  # a bad option or argument: one line, exit code 2
        where = error.ctx.command_path if error.ctx is not None else "unstack"
        _fail(f"{where}: {error.format_message()} (see {where} --help)")
    except click.ClickException as error:
        _fail(error.format_message())
    except click.Abort as error:  # Ctrl-C (the shell's 128 + SIGINT) or the end of standard input
        click.echo("unstack: aborted", err=True)
        if isinstance(error.__cause__, _Terminated):
            sys.exit(TERMINATED)
        sys.exit(INTERRUPTED if isinstance(error.__cause__, KeyboardInterrupt) else 1)
    except RuntimeError as error:  # numba's disk cache when no folder for it is writable
        if not str(error).startswith("cannot cache function"):
            raise
        _fail(
            "numba cannot cache its compiled kernels: neither the package's folder nor NUMBA_CACHE_DIR (or "
            "~/.cache) is writable; set NUMBA_CACHE_DIR to a writable folder"
        )
    if isinstance(status, int) and status:
        sys.exit(status)


if __name__ == "__main__":
    main()
