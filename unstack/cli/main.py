"""``unstack`` commands: ``decide``, ``worlds``, ``validate``, ``simulate``, ``render``,
``train``, ``evaluate``, ``probabilities``.

Each command is a thin layer over the library: read and validate the input, call one
library function, render the result. ``UnstackError`` (and unwritable outputs) become a
single ``unstack: error: ...`` line on stderr with exit code 2.
"""

from __future__ import annotations

import json
import sys
from collections.abc import Callable
from typing import Any

import click
from rich.console import Console

from unstack.cli.learning import MODEL_HELP
from unstack.errors import UnstackError
from unstack.reasoner.costs import COSTS, DEFAULT_COST

__all__ = ["cli", "main"]

INPUT_HELP = "An unstack.supports/1 or unstack.scene/1 JSON file; '-' reads standard input."


def _fail(message: str) -> None:
    click.echo(f"unstack: error: {message}", err=True)
    sys.exit(2)


class _Group(click.Group):
    """A click group that turns library errors into one line and exit code 2."""

    def invoke(self, ctx: click.Context) -> Any:
        try:
            return super().invoke(ctx)
        except UnstackError as error:
            _fail(str(error))
        except OSError as error:
            _fail(f"{getattr(error, 'filename', None) or ''}: {error.strerror or error}".lstrip(": "))
        return None


def _write_output(path: str | None, document: dict[str, Any]) -> None:
    if path is None:
        return
    from unstack.jsonio import atomic_write_text

    atomic_write_text(path, json.dumps(document, indent=2) + "\n")


def _emit(as_json: bool, document: dict[str, Any], render: Callable[[], Any]) -> None:
    if as_json:
        click.echo(json.dumps(document, indent=2))
    else:
        Console(highlight=False).print(render())


def _load_supports(path: str, model_path: str | None = None) -> Any:
    """Supports from a supports file, or from a scene file through the learned model."""
    from unstack import load
    from unstack.scene import Scene

    loaded = load(path)
    if isinstance(loaded, Scene):
        from unstack.cli.learning import scene_supports

        return scene_supports(loaded, model_path)
    return loaded


def _reasoning_options(command: Callable[..., Any]) -> Callable[..., Any]:
    """The options shared by ``decide`` and ``plan``: method, cost, sampling budget, seed."""
    options = [
        click.option(
            "--method",
            type=click.Choice(["auto", "exact", "sat", "approx"]),
            default="auto",
            show_default=True,
            help="exact: weighted preorder counting (<= 8 boxes per group); sat: list worlds with CaDiCaL "
            "(<= 6); approx: sampling with standard errors (<= 63); auto: per group, the fastest that fits.",
        ),
        click.option(
            "--cost",
            type=click.Choice(list(COSTS)),
            default=DEFAULT_COST,
            show_default=True,
            help="load: Eq. 11's count with each box counted with the undetected load the cloud shows on it; "
            "count: number of supported boxes (Eq. 11 exactly); mass: their total mass (needs masses).",
        ),
        click.option(
            "--time-limit",
            type=click.FloatRange(min=0.0, min_open=True),
            default=None,
            help="Seconds of sampling for the sampled groups (default 1; under 10 also samples groups of 8).",
        ),
        click.option(
            "--samples",
            type=click.IntRange(min=1),
            default=None,
            help="Recorded sweeps per sampled group instead of a time limit (reproducible with --seed).",
        ),
        click.option("--seed", type=click.IntRange(min=0), default=None, help="Seed of the sampler."),
    ]
    for option in reversed(options):
        command = option(command)
    return command


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
@_reasoning_options
@click.option("--model", "model_path", default=None, help=MODEL_HELP)
def decide(file: str, as_json: bool, output: str | None, model_path: str | None, **reasoning: Any) -> None:
    """Print which box to unload first, the expected cost of every box and P(support | consistent).

    FILE is an unstack.supports/1 file, or an unstack.scene/1 file whose detected boxes get
    their support probabilities from the learned model ('-' reads standard input).
    Groups of linked boxes too large to count are sampled: each EC then has a standard
    error, and the headline says how probable it is that the choice is truly the minimum.
    """
    from unstack.cli.render import decision_view
    from unstack.reasoner.decision import decide as decide_box

    supports = _load_supports(file, model_path)
    decision = decide_box(supports, **reasoning)
    document = decision.to_dict()
    _write_output(output, document)
    _emit(as_json, document, lambda: decision_view(decision))


@cli.command()
@click.argument("file", type=str)
@click.option("--json", "as_json", is_flag=True, help="Print every world as JSON (unstack.payoff/1).")
@click.option("-o", "--output", type=click.Path(dir_okay=False), help="Also write the JSON payoff matrix to this file.")
@click.option("--limit", type=click.IntRange(min=1), default=20, show_default=True, help="Worlds shown in the table.")
@click.option("--cost", type=click.Choice(["count", "mass"]), default="count", show_default=True)
def worlds(file: str, as_json: bool, output: str | None, limit: int, cost: str) -> None:
    """Print the payoff matrix (Table II): consistent worlds, their probabilities and action costs.

    Lists worlds with a SAT solver, so it is for small scenes (up to 6 boxes).
    """
    from unstack.cli.render import payoff_view
    from unstack.reasoner.payoff import payoff_matrix

    supports = _load_supports(file)
    table = payoff_matrix(supports, cost=cost)
    objects = table.objects
    document = {
        "format": "unstack.payoff/1",
        "objects": list(objects),
        "cost": cost,
        "consistent_worlds": len(table.worlds),
        "expected_costs": table.expected_costs().tolist(),
        "worlds": [
            {
                "probability": float(table.worlds.probabilities[i]),
                "supports": [[objects[x], objects[y]] for x, y in zip(*table.worlds.worlds[i].nonzero(), strict=True)],
                "costs": table.costs[i].tolist(),
            }
            for i in range(len(table.worlds))
        ],
    }
    _write_output(output, document)
    _emit(as_json, document, lambda: payoff_view(table, limit))


@cli.command()
@click.argument("file", type=str)
@click.option("--json", "as_json", is_flag=True, help="Print the plan as unstack.plan/1 JSON.")
@click.option("-o", "--output", type=click.Path(dir_okay=False), help="Also write the JSON plan to this file.")
@_reasoning_options
@click.option("--model", "model_path", default=None, help=MODEL_HELP)
def plan(file: str, as_json: bool, output: str | None, model_path: str | None, **reasoning: Any) -> None:
    """Order all detected boxes by repeated decisions: pick, remove from the set, decide again.

    With sampling, --time-limit applies to each step.
    """
    from rich.table import Table

    from unstack.reasoner.plan import unloading_plan

    supports = _load_supports(file, model_path)
    result = unloading_plan(supports, **reasoning)
    document = result.to_dict()
    _write_output(output, document)

    def view() -> Table:
        table = Table(title="Unloading plan (each step decided on the boxes still in place)", title_justify="left")
        sampled = any(step.decision.sampling is not None for step in result.steps)
        columns = ("step", "unload", "EC", *(("± s.e.", "P(minimum)") if sampled else ()), "boxes in place")
        for column in columns:
            table.add_column(column, justify="right" if column != "unload" else "left")
        for number, step in enumerate(result.steps, start=1):
            errors = (f"{step.expected_cost_error:.4f}", f"{step.decision.choice_probability:.3f}") if sampled else ()
            table.add_row(str(number), step.choice, f"{step.expected_cost:.4f}", *errors, str(len(step.remaining)))
        return table

    _emit(as_json, document, view)


@cli.command()
@click.argument("files", nargs=-1, required=True, type=str)
def validate(files: tuple[str, ...]) -> None:
    """Check files against their schema (supports, scene, decision, plan, data set manifest)."""
    from unstack.jsonio import read_document, validate_document
    from unstack.scene import Scene
    from unstack.supports import Supports

    for file in files:
        document = read_document(file)
        tag = validate_document(document)
        if tag == "unstack.supports/1":
            supports = Supports.from_document(document)
            detail = f"{supports.n_objects} objects"
        elif tag == "unstack.scene/1":
            scene = Scene.from_document(document)
            detail = f"{len(scene.boxes)} boxes, {len(scene.detected)} detected, {len(scene.points):,} points"
        elif tag == "unstack.plan/1":
            detail = f"{len(document.data['order'])} boxes in order"
        elif tag == "unstack.dataset/1":
            detail = f"{document.data['configs']} configurations, seed {document.data['seed']}"
        else:
            detail = f"choice {document.data['choice']!r}"
        click.echo(f"{document.source}: valid {tag} ({detail})")


def _register_commands() -> None:
    from unstack.cli.experiments import experiment
    from unstack.cli.learning import evaluate, probabilities, train
    from unstack.cli.simulation import render, simulate

    for command in (simulate, render, train, evaluate, probabilities, experiment):
        cli.add_command(command)


_register_commands()


def _warning_line(message: Warning | str, category: type[Warning], *_: object, **__: object) -> None:
    """Library warnings (an empty point cloud, say) as one line on stderr, without source lines."""
    click.echo(f"unstack: warning: {message}", err=True)


def main() -> None:
    """Console-script entry point."""
    import warnings

    warnings.showwarning = _warning_line
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
    except click.Abort:
        click.echo("unstack: aborted", err=True)
        sys.exit(1)
    if isinstance(status, int) and status:
        sys.exit(status)


if __name__ == "__main__":
    main()
