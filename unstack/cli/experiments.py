"""``unstack experiment``: the paper's results, reproduced from existing data sets."""

from __future__ import annotations

import functools
from collections.abc import Callable
from pathlib import Path
from typing import Any

import click
from rich.console import Console
from rich.table import Table

from unstack.cli.learning import FEATURES_HELP, ISETS_FROM_HELP
from unstack.cli.main import SAMPLES, SECONDS, STATICS_HELP, data_dir_argument, model_path_option, out_folder_option
from unstack.cli.options import Checked, constrained, scheduler_option
from unstack.cli.progress import progress_bar
from unstack.cli.text import number_table
from unstack.errors import UnstackError
from unstack.experiments.belief_calibration import belief_calibration
from unstack.experiments.camera_roundtrip import TILTED_DEG, camera_roundtrip
from unstack.experiments.container import (
    CONTAINER_SAMPLES,
    DEFAULT_CONTAINER_MAKERS,
    ORACLE_MAKERS,
    TRIED_MAKERS,
    container_experiment,
)
from unstack.experiments.decisions import evaluate_decisions
from unstack.experiments.disturbance_training import train_disturbance
from unstack.experiments.fig5a import fig5a as fig5a_experiment
from unstack.experiments.generalisation import PICKS
from unstack.experiments.outputs import results_folder, save_results
from unstack.experiments.pick_responses import collect_pick_responses, collected_piles, pick_table
from unstack.experiments.real7 import real7 as real7_experiment
from unstack.experiments.table1 import TABLE_SIZE
from unstack.experiments.unloading import UNLOAD_SAMPLES, unloading_experiment
from unstack.reasoner.costs import DEFAULT_COST

__all__ = ["experiment"]


# The option types of each experiment's arguments: the constraints the library function declares.
FIG5A = functools.partial(constrained, fig5a_experiment)
DECISIONS = functools.partial(constrained, evaluate_decisions)
REAL7 = functools.partial(constrained, real7_experiment)
UNLOAD = functools.partial(constrained, unloading_experiment)
CONTAINER = functools.partial(constrained, container_experiment)
ROUNDTRIP = functools.partial(constrained, camera_roundtrip)
CALIBRATION = functools.partial(constrained, belief_calibration)
RESPONSES = functools.partial(constrained, collect_pick_responses)
PICK_TABLE = functools.partial(constrained, pick_table)
TRAINING = functools.partial(constrained, train_disturbance)


@click.group()
def experiment() -> None:
    """Reproduce the paper's tables and figures (results as JSON and PNG in --out).

    Defaults are small (seconds to minutes), but for container's default makers: the physics
    look-ahead and the belief makers take minutes a pile of 30-40 boxes (--makers
    unstack,highest: seconds). --full runs the paper's size. real7 always scores every ISet
    of r = 3, 4, 5 of each pile, as the paper.
    """


def _seed_option(checked: Any, what: str) -> Callable[[Any], Any]:
    """An experiment's ``--seed`` (checked by ``checked``, default 0): the seed of ``what``."""
    return click.option("--seed", type=checked, default=0, show_default=True, help=f"Seed of {what}.")


def _jobs_option(checked: Any, meaning: str = "Piles run in parallel.") -> Callable[[Any], Any]:
    """An experiment's ``--jobs`` (checked by ``checked``, default 1)."""
    return click.option("--jobs", type=checked, default=1, show_default=True, help=meaning)


def _iset_options(checked: Callable[[str], Any], *, isets: int, isets_help: str) -> Callable[[Any], Any]:
    """The options of an experiment on ISets: ``--r`` boxes each, ``--isets`` of them (``isets`` by
    default), drawn as ``--isets-from`` says; ``checked`` gives each the constraints of the library
    function it is passed to."""

    def decorate(command: Any) -> Any:
        options = (
            click.option("--r", "r", type=checked("r"), default=5, show_default=True, help="Boxes per ISet."),
            click.option("--isets", type=checked("isets"), default=isets, show_default=True, help=isets_help),
            click.option(
                "--isets-from", "draw", type=checked("draw"), default="random", show_default=True, help=ISETS_FROM_HELP
            ),
        )
        for option in reversed(options):
            command = option(command)
        return command

    return decorate


def _paired(difference: dict[str, float | None] | None) -> str:
    """``+0.16 ± 0.08``: a paired difference and its standard error (blank for unstack itself)."""
    if difference is None:
        return ""
    error = difference["standard_error"]
    return f"{difference['mean']:+.2f}" + ("" if error is None else f" ± {error:.2f}")


def _results_in(paths: list[Path]) -> str:
    """``results in a.json and a.png``."""
    return "results in " + " and ".join(str(path) for path in paths)


def _print_results(table: Table, written: list[Path] | None = None, *lines: str) -> None:
    """Print an experiment's table, then ``lines``, then where its results were written."""
    Console().print(table)
    for line in lines:
        click.echo(line)
    if written is not None:
        click.echo(_results_in(written))


def _run_piles(
    run: Callable[..., dict[str, Any]], scheduler: str | None, out: str, checkpoints: str, **arguments: Any
) -> tuple[Path, dict[str, Any]]:
    """Run an experiment on piles (on a dask.distributed scheduler's workers when given one) with a
    progress bar, each pile's result kept in ``OUT/checkpoints``: the results folder and the result."""
    from unstack.sim.dataset import scheduler_client
    from unstack.sim.progress import watching_picks

    with scheduler_client(scheduler, arguments.get("n_jobs", 1)) as client:  # fails in seconds, before any output
        folder = results_folder(out)
        with watching_picks() as picks, progress_bar("piles", within=picks.line) as report:
            result = run(**arguments, progress=report, checkpoints=folder / checkpoints, client=client)
    return folder, result


@experiment.command()
@out_folder_option("Folder for table1.json.")
@click.option("--max-n", type=Checked(int, functools.partial(TABLE_SIZE.check, name="max_n")), default=6,
              show_default=True, help="Largest n (3 to 8; 7 takes seconds, 8 minutes).")  # fmt: skip
@click.option("--full", is_flag=True, help="The paper's size: n = 3..7 (overrides --max-n).")
def table1(out: str, max_n: int, full: bool) -> None:
    """Table I: consistent worlds for n = 3..max-n by the exact engine and SAT, against the paper and OEIS."""
    from unstack.experiments.table1 import table1 as count

    if full:
        max_n = 7
    rows = count(range(3, max_n + 1))
    save_results(results_folder(out), "table1.json", rows)
    figures = (
        (
            str(row["n"]),
            f"{row['all_worlds']:,}",
            f"{row['exact']:,}",
            f"{row['sat']:,}" if "sat" in row else "-",
            f"{row['paper']:,}" if row["paper"] else "-",
            f"{row['oeis']:,}",
        )
        for row in rows
    )
    header = ("n", "all worlds q", "exact engine", "SAT listing", "paper", "OEIS A000798")
    _print_results(number_table("Table I: consistent worlds q' of n boxes", header, figures))


@experiment.command(short_help="Fig. 5a: the validation confusion matrix of the SVM, beside the paper's.")
@data_dir_argument
@out_folder_option("Folder for fig5a.json.")
@_iset_options(FIG5A, isets=1, isets_help="ISets per configuration.")
@click.option("--learner", type=FIG5A("learner"), default="svm",
              show_default=True, help="svm: the paper's RBF SVM with probabilities.")  # fmt: skip
@click.option("--split-by", type=FIG5A("split_by"), default="pairs", show_default=True,
              help="pairs: the paper's split of the relations; configuration: whole piles on one side.")  # fmt: skip
@click.option("--features", "feature_set", type=FIG5A("feature_set"), default="paper",
              show_default=True, help=FEATURES_HELP)  # fmt: skip
@_seed_option(FIG5A("seed"), "the ISets, split and folds")
@click.option("--cv", type=FIG5A("cv"), default=10, show_default=True,
              help="Cross-validation folds.")  # fmt: skip
@_jobs_option(FIG5A("n_jobs"), "Parallel processes.")
@click.option("--full", is_flag=True, help="Insist on the paper's size: at least 200 configurations, 10 folds.")
def fig5a(
    data_dir: str,
    out: str,
    r: int,
    isets: int,
    draw: str,
    learner: str,
    split_by: str,
    feature_set: str,
    seed: int,
    cv: int,
    jobs: int,
    full: bool,
) -> None:
    """Fig. 5a: the validation confusion matrix of the SVM on a simulated data set, beside the paper's."""
    from unstack.dataset_folders import require_configurations
    from unstack.experiments.fig5a import plot_fig5a, require_paper_size

    require_configurations(data_dir)
    if full:
        require_paper_size(data_dir, cv)
    from unstack.cli.progress import still_working

    with still_working("fig5a: features and cross-validation"):
        result = fig5a_experiment(
            data_dir, r=r, isets=isets, seed=seed, cv=cv, n_jobs=jobs, draw=draw, learner=learner,
            split_by=split_by, feature_set=feature_set,
        )  # fmt: skip
    written = save_results(results_folder(out), "fig5a.json", result, plot_fig5a)
    table = number_table(
        f"Fig. 5a: validation relations of {data_dir} ({result['relations']} relations, {result['supp']} SUPP)",
        ("", "SUPP right", "not SUPP right"),
    )
    ours = result["validation"]
    balanced = result["validation_at_balanced_threshold"]
    table.add_row("paper (Fig. 5a)", "78.4 %", "87.5 %")
    table.add_row(
        f"unstack {learner}, P >= 0.5", f"{100 * ours['supp_recall']:.1f} %", f"{100 * ours['not_supp_recall']:.1f} %"
    )
    table.add_row(
        f"unstack, P >= {result['balanced_threshold']:.3f} (balanced on training part)",
        f"{100 * balanced['supp_recall']:.1f} %",
        f"{100 * balanced['not_supp_recall']:.1f} %",
    )
    operating = result["validation_at_paper_recall_threshold"]
    table.add_row(
        f"unstack, P >= {result['paper_recall_threshold']:.3f} (paper's SUPP recall on training part)",
        f"{100 * operating['supp_recall']:.1f} %",
        f"{100 * operating['not_supp_recall']:.1f} %",
    )
    table.add_row(
        "unstack, validation ROC at the paper's SUPP recall",
        "78.4 %",
        f"{100 * result['validation_roc']['not_supp_recall_at_paper_supp_recall']:.1f} %",
    )
    _print_results(table, written)


@experiment.command(short_help="Fig. 4 and beyond: MSE(cost), first pick right, disturbance per decision maker.")
@data_dir_argument
@out_folder_option("Folder for decisions.json and fig4.png.")
@model_path_option
@_iset_options(DECISIONS, isets=50, isets_help="Test ISets (the paper: 493).")
@_seed_option(DECISIONS("seed"), "the ISets")
@click.option("--full", is_flag=True, help="The paper's size: 493 test ISets (overrides --isets).")
@click.option("--pair-with", "pair_with", type=click.Path(dir_okay=False), default=None,
              help="decisions.json of an earlier run on the same ISets (another model, say): "
                   "prints unstack's boxes moved, this run minus that one, paired.")  # fmt: skip
@click.option("--statics/--no-statics", default=True, show_default=True, help=STATICS_HELP)
def decisions(
    data_dir: str,
    out: str,
    model_path: str | None,
    r: int,
    isets: int,
    draw: str,
    seed: int,
    full: bool,
    pair_with: str | None,
    statics: bool,
) -> None:
    """Fig. 4 and beyond: MSE(cost), first pick right and physical disturbance of every decision maker."""
    from unstack.cli.main import load_model_option
    from unstack.dataset_folders import require_configurations
    from unstack.experiments.decisions import (
        DECISION_MAKERS,
        PAPER_TEST_ISETS,
        check_decisions_run,
        paired_between_runs,
        plot_fig4,
    )
    from unstack.jsonio import read_document

    if full:
        isets = PAPER_TEST_ISETS
    require_configurations(data_dir)  # before any progress bar or output folder
    earlier = read_document(pair_with).data if pair_with is not None else None
    if earlier is not None:
        from unstack.dataset_folders import dataset_digest, list_configurations
        from unstack.experiments.decisions import require_same_draw

        this = {"data": str(data_dir), "r": r, "seed": seed, "draw": draw}
        if "data_sha256" in earlier:
            this["data_sha256"] = dataset_digest(list_configurations(data_dir))
        try:
            check_decisions_run(earlier)  # before the run, not after it
            require_same_draw(earlier, this)
        except ValueError as error:
            raise UnstackError(f"{pair_with}: {error}") from None
    model, name = load_model_option(model_path)
    folder = results_folder(out)
    with progress_bar("ISets") as report:
        result = evaluate_decisions(
            data_dir, model, r=r, isets=isets, seed=seed, progress=report, draw=draw, statics=statics
        )
    result["model"] = name
    if earlier is not None:
        try:
            result["against_earlier_run"] = {"file": str(pair_with), **paired_between_runs(earlier, result)}
        except ValueError as error:
            raise UnstackError(f"{pair_with}: {error}") from None
    written = save_results(folder, "decisions.json", result, plot_fig4, "fig4.png")
    summary, against = result["summary"], result["against_reasoner"]
    figures = (
        (
            maker,
            f"{summary[maker]['mse_cost']:.3f}",
            f"{100 * summary[maker]['first_pick_right']:.1f} %",
            f"{summary[maker]['boxes_moved']:.2f}",
            _paired(against.get(maker, {}).get("boxes_moved")),
            f"{summary[maker]['displacement_m']:.3f}",
        )
        for maker in DECISION_MAKERS
    )
    header = ("decision maker", "MSE(cost)", "first pick right", "boxes moved > 2 cm", "moved - unstack's (± s.e.)",
              "displacement (m)")  # fmt: skip
    table = number_table(f"{result['isets']} test ISets of {r} boxes ({data_dir})", header, figures)
    earlier_line = () if earlier is None else (
        f"unstack's boxes moved, this run minus {pair_with}: {_paired(result['against_earlier_run'])}",
    )  # fmt: skip
    _print_results(table, written, *earlier_line)


@experiment.command()
@data_dir_argument
@out_folder_option("Folder for real7.json.")
@click.option("--model", "model_path", default=None,
              help="Model file or shipped model's name (default: the default model, general).")  # fmt: skip
@click.option("--piles", type=REAL7("piles"), default=None, help="Use only the first N piles (default: all).")
def real7(data_dir: str, out: str, model_path: str | None, piles: int | None) -> None:
    """The paper's real setting in simulation: every ISet of r = 3, 4, 5 of each 7-box pile."""
    from unstack.cli.main import load_model_option
    from unstack.dataset_folders import require_configurations
    from unstack.experiments.real7 import summary_rows

    require_configurations(data_dir)
    model, name = load_model_option(model_path)
    with progress_bar("ISets") as report:
        result = real7_experiment(data_dir, model, piles=piles, progress=report)
    result["model"] = name
    written = save_results(results_folder(out), "real7.json", result)
    table = number_table(
        f"first pick right, {result['piles']} simulated {'pile' if result['piles'] == 1 else 'piles'} ({data_dir})",
        ("r", "ISets", "paper", "unstack", "highest first", "random"),
        summary_rows(result),
    )
    worst = {maker: "-" if mse is None else f"{mse:.3f}" for maker, mse in result["worst_mse"].items()}
    _print_results(
        table,
        written,
        f"worst MSE(cost) over r: unstack {worst['reasoner']}, random {worst['random']} (paper 0.5 vs 3.5)",
    )


@experiment.command()
@data_dir_argument
@out_folder_option("Folder for unloading.json and unloading.png.")
@model_path_option
@click.option("--configs", type=UNLOAD("configs"), default=4, show_default=True, help="Piles (the first N).")
@click.option("--samples", type=SAMPLES, default=UNLOAD_SAMPLES, show_default=True,
              help="Recorded sweeps per sampled group in each decision (reproducible with the seed).")  # fmt: skip
@click.option("--time-limit", type=SECONDS, default=None,
              help="Seconds per decision instead of the default --samples; with --samples given too, whichever "
              "ends first (not reproducible).")  # fmt: skip
@_seed_option(UNLOAD("seed"), "the sampler and the random order")
@click.option("--full", is_flag=True, help="Every configuration of the data set (overrides --configs).")
@click.option("--cost", type=UNLOAD("cost"), default=DEFAULT_COST, show_default=True,
              help="Cost of unstack's decisions: load (hidden load counted), count (Eq. 11) or mass.")  # fmt: skip
@click.option("--closed-loop", is_flag=True,
              help="Also unstack and highest-first sensing the pile again before each pick (3x slower).")  # fmt: skip
@click.option("--statics/--no-statics", default=True, show_default=True, help=STATICS_HELP)
@_jobs_option(UNLOAD("n_jobs"))
@scheduler_option("piles")
def unload(
    data_dir: str,
    out: str,
    model_path: str | None,
    configs: int,
    samples: int,
    time_limit: float | None,
    seed: int,
    full: bool,
    cost: str,
    closed_loop: bool,
    statics: bool,
    jobs: int,
    scheduler: str | None,
) -> None:
    """Order every detected box of each pile and execute the orders in the simulator, box by box.

    Resumable: each pile's result is kept in OUT/unloading-piles as soon as it is done, and a
    run started again with the same piles, model, time limit and seed reuses them.
    """
    from unstack.cli.main import load_model_option
    from unstack.dataset_folders import require_configurations
    from unstack.experiments.unloading import plot_unloading

    found = len(require_configurations(data_dir))
    if full:
        configs = found
    model, name = load_model_option(model_path)
    given = click.get_current_context().get_parameter_source("samples") == click.core.ParameterSource.COMMANDLINE
    folder, result = _run_piles(  # with both given, each decision stops at whichever ends first, as plan's
        unloading_experiment, scheduler, out, "unloading-piles", data_dir=data_dir, model=model, configs=configs,
        samples=samples if given or not time_limit else None, time_limit=time_limit, seed=seed, closed_loop=closed_loop,
        cost=cost, statics=statics, n_jobs=jobs,
    )  # fmt: skip
    result["model"] = name
    written = save_results(folder, "unloading.json", result, plot_unloading)
    summary, against = result["summary"], result["against_reasoner"]
    figures = (
        (
            maker,
            f"{summary[maker]['boxes_moved_per_pile']:.2f}",
            _paired(against.get(maker, {}).get("boxes_moved")),
            f"{summary[maker]['boxes_moved_per_pick']:.3f}",
            f"{100 * summary[maker]['calm_picks']:.1f} %",
            f"{summary[maker]['displacement_m_per_pile']:.3f}",
        )
        for maker in result["makers"]
    )
    from unstack.sim.settings import DISPLACEMENT_THRESHOLD, ROTATION_THRESHOLD_DEG

    moved = f"boxes moved (> {100 * DISPLACEMENT_THRESHOLD:g} cm or {ROTATION_THRESHOLD_DEG:g}°) per pile"
    header = ("decision maker", moved, "minus unstack's (± s.e.)", "per pick",
              "picks moving nothing", "displacement (m)")  # fmt: skip
    title = f"Unloading every detected box of {result['configs']} piles ({data_dir}) in the simulator"
    _print_results(number_table(title, header, figures), written)


@experiment.command()
@data_dir_argument
@out_folder_option("Folder for container.json.")
@model_path_option
@click.option("--piles", type=CONTAINER("piles"), default=2, show_default=True, help="Piles (the first N).")
@click.option("--makers", default=",".join(DEFAULT_CONTAINER_MAKERS), show_default=True,
              help=f"Comma-separated decision makers; the oracles {', '.join(ORACLE_MAKERS)} (they read every box "
              f"of the pile, for diagnosis) and {', '.join(TRIED_MAKERS)} (slow; see the results page) "
              "run only when named.")  # fmt: skip
@click.option("--detector-noise", type=CONTAINER("detector_noise"), default=0.0, show_default=True,
              help="Position error of the box detector (m); yaw errors follow.")  # fmt: skip
@click.option("--detector-misses", type=CONTAINER("detector_misses"), default=0.0, show_default=True,
              help="Share of the seen boxes the detector misses at each scan.")  # fmt: skip
@click.option(
    "--reach",
    type=CONTAINER("reach"),
    default="door",
    show_default=True,
    help="door: a box whose door-facing side or top is at most half covered; any: every detected box.",
)
@click.option("--max-picks", type=CONTAINER("max_picks"), default=None, help="Stop each pile after this many picks.")
@click.option("--samples", type=SAMPLES, default=CONTAINER_SAMPLES, show_default=True,
              help="Recorded sweeps per sampled group in each decision.")  # fmt: skip
@_seed_option(
    CONTAINER("seed"), "the decisions' sampling, the belief worlds and the detector's misses (pile N: seed + N)"
)
@_jobs_option(CONTAINER("n_jobs"))
@scheduler_option("piles")
@click.option("--disturbance", "disturbance_path", type=click.Path(dir_okay=False, exists=True), default=None,
              help="Disturbance model file of the moves maker (default: the shipped one).")  # fmt: skip
@click.option("--occupancy", type=CONTAINER("occupancy"), default=None,
              help="Share of the unseen space the sampled belief of belief_sampled and belief_sampled_veto keeps "
              "solid (default: unstack.sim.belief.OCCUPANCY; belief_scaled_veto and belief_faces_veto take it from "
              "the scene).")  # fmt: skip
def container(
    data_dir: str,
    out: str,
    model_path: str | None,
    piles: int,
    makers: str,
    detector_noise: float,
    detector_misses: float,
    reach: str,
    max_picks: int | None,
    samples: int,
    seed: int,
    jobs: int,
    scheduler: str | None,
    disturbance_path: str | None,
    occupancy: float | None,
) -> None:
    """Empty whole containers as a robot does: scan and detect again before every pick.

    Every decision maker unloads the same piles; boxes moved, fallen and calm picks are
    compared with unstack's (paired over piles). Resumable: OUT/container-piles keeps each
    pile's result. The default makers take minutes a pile of 30-40 boxes (the look-ahead tries
    every candidate in the engine); --makers unstack,highest takes about 15 s. With --jobs 1
    the progress says which maker empties which pile, and how far.
    """
    from unstack.cli.main import load_model_option
    from unstack.dataset_folders import require_configurations
    from unstack.experiments.container import container_policies

    require_configurations(data_dir)
    chosen = tuple(name.strip() for name in makers.split(",") if name.strip())
    if not chosen:
        raise UnstackError(f"--makers: expected decision makers separated by commas, got {makers!r}")
    twice = sorted({name for name in chosen if chosen.count(name) > 1})
    if twice:
        raise UnstackError(f"--makers: {twice[0]!r} is named twice")
    model, name = load_model_option(model_path)
    container_policies(model, seed=seed, makers=chosen)  # an unknown maker is one line, before any work
    if disturbance_path is not None:  # the moves maker reads it in every pile: a bad file is refused now
        from unstack.learning.disturbance import load_disturbance_model

        load_disturbance_model(disturbance_path)
    folder, result = _run_piles(
        container_experiment, scheduler, out, "container-piles", data_dir=data_dir, model=model, piles=piles,
        makers=chosen, detector_noise=detector_noise, detector_misses=detector_misses, reach=reach,
        max_picks=max_picks, samples=samples, seed=seed, n_jobs=jobs, disturbance=disturbance_path,
        occupancy=occupancy,
    )  # fmt: skip
    result["model"] = name
    written = save_results(folder, "container.json", result)
    summary, against = result["summary"], result["against_unstack"]
    figures = (
        (
            maker,
            f"{summary[maker]['picks_per_pile']:.1f}",
            f"{summary[maker]['boxes_moved_per_pile']:.2f}",
            _paired(against.get(maker, {}).get("boxes_moved")),
            f"{summary[maker]['boxes_fallen_per_pile']:.2f}",
            _paired(against.get(maker, {}).get("boxes_fallen")),
            f"{100 * summary[maker]['calm_picks_per_pile']:.0f} %",
        )
        for maker in result["makers"]
    )
    from unstack.sim.settings import DISPLACEMENT_THRESHOLD, ROTATION_THRESHOLD_DEG

    header = ("decision maker", "picks", "boxes moved", "minus unstack's", "fallen", "minus unstack's", "calm")
    title = f"Emptying {result['piles']} piles of {data_dir}, detecting again before every pick"
    legend = (
        f"per pile: picks, boxes moved (more than {100 * DISPLACEMENT_THRESHOLD:g} cm or {ROTATION_THRESHOLD_DEG:g} "
        "degrees) and fallen over all picks; minus unstack's: the "
        "difference from unstack's on the same piles, ± its standard error over piles; calm: the share of "
        "picks that moved no other box"
    )
    _print_results(number_table(title, header, figures), written, legend)


@experiment.command()
@out_folder_option("Folder for generalisation.json and the pictures.")
@model_path_option
@click.option("--seeds", type=click.IntRange(min=1), default=3, show_default=True, help="Scenes drawn per kind.")
@click.option("--first-seed", type=click.IntRange(min=0), default=0, show_default=True,
              help="Seed of the first scene of each kind (later ones follow).")  # fmt: skip
@click.option("--physics", is_flag=True, help="Also check each scene's labels in the physics engine.")
@click.option("--pick", type=click.Choice(list(PICKS)), default="default", show_default=True,
              help="default: the highest box of EC below 0.5, else near ties (unstack decide's pick); near-ties: the "
                   "reasoner's choice (near ties to the box resting highest); min-cost: the minimum EC (Eq. 12); "
                   "hybrid: the highest box of EC below 0.5, else the minimum.")  # fmt: skip
def generalisation(out: str, model_path: str | None, seeds: int, first_seed: int, physics: bool, pick: str) -> None:
    """The generalisation suite: hand-made canonical scenes, two clouds each, the decision checked.

    Each kind (a tower, a bridge, a wall, a leaning box, load nobody detected, ...) is drawn
    --seeds times and scanned by the project's range sensor and by surface sampling; a
    decision is right when it picks a box that holds up nothing and its expected costs keep
    their bounds. Writes generalisation.json and generalisation.png (one scene per kind).
    """
    from unstack.cli.main import load_model_option
    from unstack.experiments.canonical_scenes import CANONICAL_KINDS, build_case
    from unstack.experiments.generalisation import physical_check, picked, run_suite, suite_figure, summary_rows
    from unstack.pipeline import scene_support_probabilities
    from unstack.reasoner.decision import decide

    folder = results_folder(out)
    model, name = load_model_option(model_path)
    seed_list = list(range(first_seed, first_seed + seeds))
    with progress_bar("scenes") as report:
        results = run_suite(
            lambda scene: picked(
                decide(scene_support_probabilities(scene, model, model_name=name), seed=0), scene, pick
            ),
            seeds=seed_list,
            progress=report,
        )
    physics_problems = {}
    if physics:
        for kind in CANONICAL_KINDS:
            for seed in seed_list:
                problems = physical_check(build_case(kind, seed=seed))
                if problems:
                    physics_problems[f"{kind} seed {seed}"] = problems
    rows = summary_rows(results)
    save_results(folder, "generalisation.json", {"model": name, "pick": pick, "seeds": seed_list, "summary": rows,
                 "physics": physics_problems if physics else None,
                 "decisions": [result.to_dict() for result in results]})  # fmt: skip
    first = {(r.kind, r.cloud): r for r in results if r.seed == first_seed}
    suite_figure([(build_case(kind, seed=first_seed), first[(kind, "sensor")]) for kind in CANONICAL_KINDS],
                 str(folder / "generalisation.png"))  # fmt: skip
    table = Table(title=f"Generalisation suite ({name}; {len(seed_list)} scenes per kind and cloud)")
    for column in ("kind", "cloud", "scenes", "right first pick", "within every bound"):
        table.add_column(column, justify="left" if column in ("kind", "cloud") else "right")
    for row in rows:
        table.add_row(row["kind"], row["cloud"], str(row["scenes"]), str(row["right_pick"]), str(row["right"]))
    right = sum(result.right for result in results)
    picks = sum(result.choice in result.pickable for result in results)
    console = Console()
    console.print(table)
    console.print(f"right first pick {picks}/{len(results)}; within every bound {right}/{len(results)}")
    for key, problems in physics_problems.items():
        console.print(f"physics disagrees with the labels of {key}: {'; '.join(problems)}")


@experiment.command("camera-roundtrip")
@data_dir_argument
@out_folder_option("Folder for camera-roundtrip.json.")
@model_path_option
@click.option("--piles", type=ROUNDTRIP("piles"), default=2, show_default=True, help="Piles (the first N).")
@_jobs_option(ROUNDTRIP("n_jobs"))
def camera_roundtrip_command(data_dir: str, out: str, model_path: str | None, piles: int, jobs: int) -> None:
    """Render piles as camera files, build the scenes back (unstack scene's method), compare with the truth.

    Prints the position and yaw errors of the fitted boxes, the share of sizes right and the
    share of piles whose decision on the built scene is the one on the true poses.
    """
    from unstack.cli.main import load_model_option
    from unstack.dataset_folders import require_configurations

    require_configurations(data_dir)
    model, _ = load_model_option(model_path)
    folder = results_folder(out)
    with progress_bar("piles") as report:
        result = camera_roundtrip(data_dir, model, piles=piles, n_jobs=jobs, progress=report)
    written = save_results(folder, "camera-roundtrip.json", result)
    summary = result["summary"]
    table = number_table(
        f"Camera files to scenes: {summary['boxes']} boxes fitted from {summary['masks']} masks "
        f"({summary['piles']} piles of {data_dir})",
        ("figure", "median", "90th percentile"),
    )
    table.add_row("position error (mm)", f"{1000 * summary['position_error_m_median']:.1f}",
                  f"{1000 * summary['position_error_m_p90']:.1f}")  # fmt: skip
    table.add_row(
        "yaw error (degrees)", f"{summary['yaw_error_deg_median']:.1f}", f"{summary['yaw_error_deg_p90']:.1f}"
    )
    table.add_row(
        "axis error (degrees)", f"{summary['axis_error_deg_median']:.1f}", f"{summary['axis_error_deg_p90']:.1f}"
    )
    if summary["tilted_boxes"]:
        table.add_row(
            f"position error of the {summary['tilted_boxes']} boxes lying tilted {TILTED_DEG:g} degrees or more (mm)",
            f"{1000 * summary['tilted_position_error_m_median']:.1f}",
            f"{1000 * summary['tilted_position_error_m_p90']:.1f}",
        )
    if summary["whole_boxes"]:
        table.add_row(
            f"position error of the {summary['whole_boxes']} boxes whose face was seen whole (mm)",
            f"{1000 * summary['whole_position_error_m_median']:.1f}",
            f"{1000 * summary['whole_position_error_m_p90']:.1f}",
        )
    _print_results(
        table,
        written,
        f"sizes right {100 * summary['size_right_share']:.0f} %; fitted from the top face "
        f"{100 * summary['top_faces_share']:.0f} %; the same decision as on the true poses in "
        f"{100 * summary['same_decision_share']:.0f} % of piles; the pick moves nothing in the true pile in "
        f"{100 * summary['camera_pick_moved_nothing_share']:.0f} % of piles from the camera, "
        f"{100 * summary['truth_pick_moved_nothing_share']:.0f} % from the true poses (boxes moved per pile "
        f"{summary['camera_pick_boxes_moved_mean']:.2f} and {summary['truth_pick_boxes_moved_mean']:.2f})",
    )


@experiment.command("belief-calibration")
@data_dir_argument
@out_folder_option("Folder for belief-calibration.json.")
@click.option("--piles", type=CALIBRATION("piles"), default=2, show_default=True, help="Piles (the first N).")
@click.option("--detector-misses", type=CALIBRATION("detector_misses"), default=0.0, show_default=True,
              help="Share of the seen boxes the detector misses at each scan.")  # fmt: skip
@click.option("--worlds", type=CALIBRATION("worlds"), default=None, help="Belief worlds per decision (default 4).")
@click.option("--max-picks", type=CALIBRATION("max_picks"), default=None, help="Stop each pile after this many picks.")
@_seed_option(CALIBRATION("seed"), "the detector's misses and the belief worlds")
@click.option("--fill", type=CALIBRATION("fill"), default="cloud", show_default=True,
              help="What the belief puts where no box is seen: cloud: the cloud's unexplained points; occlusion: "
                   "all the space the sensor cannot see next to the boxes; sampled: runs of it kept at a fixed "
                   "chance; scaled: at a chance scaled by its volume; faces: the space behind surfaces no "
                   "detected box explains; cartons: that, and whole hidden cartons drawn into the rest.")  # fmt: skip
@click.option("--view", type=CALIBRATION("view"), default="candidates", show_default=True,
              help="Boxes in the belief: the reachable candidates, or every box the detector reports.")  # fmt: skip
@_jobs_option(CALIBRATION("n_jobs"))
def belief_calibration_command(
    data_dir: str, out: str, piles: int, detector_misses: float, worlds: int | None, max_picks: int | None, seed: int,
    fill: str, view: str, jobs: int,
) -> None:  # fmt: skip
    """What physics on the belief expects each pick to move, against what it moves.

    Piles are emptied highest first; before every pick each candidate's removal is tried in
    the true pile and in the belief built from what the robot sees. Prints Spearman's rank
    correlation, the means per predicted bin, and what each rule's pick would have moved.
    """
    from unstack.dataset_folders import require_configurations

    require_configurations(data_dir)
    folder = results_folder(out)
    with progress_bar("piles") as report:
        result = belief_calibration(
            data_dir, piles=piles, detector_misses=detector_misses, worlds=worlds, max_picks=max_picks, seed=seed,
            fill=fill, view=view, n_jobs=jobs, progress=report,
        )  # fmt: skip
    written = save_results(folder, "belief-calibration.json", result)
    bins = (
        (
            f"{row['predicted_from']:g} - {'' if row['predicted_to'] is None else format(row['predicted_to'], 'g')}",
            str(row["picks"]),
            f"{row['mean_predicted']:.2f}",
            f"{row['mean_actual']:.2f}",
        )
        for row in result["calibration"]["bins"]
    )
    title = f"Expected against actual boxes moved per candidate ({result['piles']} piles of {data_dir})"
    picks = result["picks"]
    _print_results(
        number_table(title, ("expected", "candidates", "mean expected", "mean actual"), bins),
        written,
        f"Spearman's rank correlation: {result['calibration']['spearman']:.3f}",
        f"boxes the pick would have moved over {picks['states']} states: highest first {picks['highest']}, "
        f"the belief's fewest {picks['belief']}, height vetoed by the belief {picks['belief_veto']}, "
        f"the look-ahead's {picks['lookahead']}",
    )


@experiment.command("pick-responses")
@click.argument("data_dirs", nargs=-1, required=True, type=click.Path(file_okay=False))
@out_folder_option("Folder of the collected states (resumable).")
@click.option("--piles", type=RESPONSES("piles"), default=None,
              help="The first N piles of each data set (default: all).")  # fmt: skip
@click.option("--max-picks", type=RESPONSES("max_picks"), default=None, help="Stop each pile after this many picks.")
@_seed_option(RESPONSES("seed"), "the mixed policy's choices, its sampled decisions and the removals' order")
@click.option("--behaviour", type=RESPONSES("behaviour"), default="mixed", show_default=True,
              help="What takes the picks: mixed (the probe's best, the highest or a random box, drawn) or a "
              "decision maker of `unstack experiment container` (the states it reaches itself, as DAgger "
              "collects them).")  # fmt: skip
@model_path_option
@click.option("--disturbance", "disturbance_path", type=click.Path(dir_okay=False, exists=True), default=None,
              help="Disturbance model file of a moves maker taking the picks (default: the shipped one).")  # fmt: skip
@_jobs_option(RESPONSES("n_jobs"))
@scheduler_option("piles")
def pick_responses(
    data_dirs: tuple[str, ...], out: str, piles: int | None, max_picks: int | None, seed: int, behaviour: str,
    model_path: str | None, disturbance_path: str | None, jobs: int, scheduler: str | None,
) -> None:  # fmt: skip
    """Empty piles with a physics probe of every candidate before each pick; save every state.

    The training data of the disturbance model: each state holds the boxes, the cloud, the
    reachable candidates and what each candidate's removal moves (tried in the engine and
    undone). Which candidate is then taken: by default drawn (the probe's best, the highest, a
    random one); with --behaviour, a decision maker's pick.
    """
    from unstack.cli.main import load_model_option
    from unstack.sim.dataset import scheduler_client

    if disturbance_path is not None:  # read by a moves maker taking the picks; refused now (the library says unused)
        from unstack.learning.disturbance import load_disturbance_model

        load_disturbance_model(disturbance_path)
    model = None if behaviour == "mixed" and model_path is None else load_model_option(model_path)[0]
    with scheduler_client(scheduler, jobs) as client, progress_bar("piles") as report:
        summaries = collect_pick_responses(
            list(data_dirs), out, piles=piles, seed=seed, max_picks=max_picks, behaviour=behaviour, model=model,
            disturbance=disturbance_path, n_jobs=jobs, client=client, progress=report,
        )  # fmt: skip
    states = sum(summary["states"] for summary in summaries)
    click.echo(f"{len(summaries)} piles, {states} states in {out}")


@experiment.command("train-disturbance")
@click.argument("states", type=click.Path(file_okay=False, exists=True))
@out_folder_option("Folder for disturbance.skops and disturbance.json.")
@model_path_option
@click.option("--folds", type=TRAINING("folds"), default=5, show_default=True,
              help="Grouped folds (piles held out together) of the held-out figures.")  # fmt: skip
@_seed_option(TRAINING("random_state"), "the learner")
@_jobs_option(PICK_TABLE("n_jobs"), "Piles in parallel.")
def train_disturbance_command(states: str, out: str, model_path: str | None, folds: int, seed: int, jobs: int) -> None:
    """Fit the disturbance model (what a pick moves) on collected states; report it held out.

    Every state is seen with every reachable box detected and with a detector missing half of
    them; the held-out report gives calibration (Spearman, means per predicted bin) and what
    the held-out picks moved beside highest first, the load cost and the look-ahead.
    """
    from unstack.cli.main import load_model_option
    from unstack.learning.disturbance import save_disturbance_model

    if not collected_piles(states):  # before the results folder is made
        raise UnstackError(f"{states}: no collected states (unstack experiment pick-responses writes them)")
    model, name = load_model_option(model_path)
    folder = results_folder(out)
    with progress_bar("piles") as report:
        records = pick_table(states, model, seed=seed, n_jobs=jobs, progress=report)
    disturbance, result = train_disturbance(records, random_state=seed, folds=folds)
    disturbance.metadata["training"] = {"states": str(states), "support_model": name, "seed": seed}
    save_disturbance_model(disturbance, folder / "disturbance.skops")
    save_results(folder, "disturbance.json", result)
    scores = (
        (key, str(row["states"]), *(f"{row[policy]:.3f}" for policy in ("highest", "load", "moves", "lookahead")))
        for key, row in result["pick_scores"].items()
    )
    _print_results(
        number_table(
            f"Boxes the next pick moved, held out ({result['piles']} piles, {result['records']} views)",
            ("family / view", "states", "highest", "load cost", "moves", "look-ahead"),
            scores,
        ),
        None,
        f"Spearman's rank correlation, predicted against actual: {result['calibration']['spearman']:.3f}",
        f"model in {folder / 'disturbance.skops'}, report in {folder / 'disturbance.json'}",
    )
