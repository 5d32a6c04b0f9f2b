"""``unstack train``, ``unstack evaluate``, ``unstack probabilities``: the learned support model."""

from __future__ import annotations

import functools
import math
import os
from pathlib import Path
from typing import Any

import click
from rich.console import Console, Group
from rich.table import Table
from rich.text import Text

from unstack.cli.main import STATICS_HELP, data_dir_argument, model_path_option
from unstack.cli.options import Checked, constrained
from unstack.cli.text import counted
from unstack.errors import UnstackError
from unstack.jsonio import report_text
from unstack.learning.choices import LEARNERS, SPLITS
from unstack.learning.features import FEATURE_SETS
from unstack.learning.training_data import ISET_DRAWS, dataset_examples
from unstack.parameters import LEARNING_SEED, MAX_FOLDS, MAX_JOBS

__all__ = ["evaluate", "load_support_model", "metrics_view", "probabilities", "scene_supports", "train"]


def load_support_model(path: str | None) -> tuple[Any, str]:
    """The model of ``--model`` and its name (:func:`unstack.api.load_model`: a file, a shipped
    model's name, or the default model when None)."""
    from unstack.cli.main import load_model_option

    return load_model_option(path)


def scene_supports(scene: Any, model_path: str | None, statics: bool = True) -> Any:
    """Support probabilities of a scene's detected boxes (:func:`unstack.support_probabilities`)."""
    from unstack.api import support_probabilities

    return support_probabilities(scene, model_path, statics=statics)


def metrics_view(report: dict[str, Any], title: str) -> Group:
    """The paper's Fig. 5 confusion matrix and the summary metrics."""
    counts = report["confusion_matrix"]
    confusion = Table(title=title, title_justify="left")
    confusion.add_column("actual \\ predicted")
    confusion.add_column("SUPP", justify="right")
    confusion.add_column("not SUPP", justify="right")
    for label, row in (("SUPP", counts[0]), ("not SUPP", counts[1])):
        total = max(sum(row), 1)
        confusion.add_row(label, *(f"{value} ({100 * value / total:.1f} %)" for value in row))
    summary = Table(show_header=False, box=None)
    for key, label in (
        ("relations", "relations"),
        ("success_rate", "success rate"),
        ("balanced_error_rate", "balanced error rate (Eq. 16)"),
        ("average_entropy", "average entropy (Eq. 15)"),
        ("brier_score", "Brier score"),
        ("expected_calibration_error", "expected calibration error"),
    ):
        value = report[key]
        shown = "n/a" if value is None or (isinstance(value, float) and math.isnan(value)) else value
        summary.add_row(label, f"{shown:.4f}" if isinstance(shown, float) else str(shown))
    return Group(confusion, summary)


def data_sets_view(reports: dict[str, dict[str, Any]]) -> Table:
    """The hold-out figures of each pooled data set: relations, the two recalls at 0.5, ECE."""
    table = Table(title="hold-out figures by data set", title_justify="left")
    for column in ("data set", "relations", "SUPP", "SUPP recall", "not-SUPP recall", "ECE"):
        table.add_column(column, justify="left" if column == "data set" else "right")
    for name, report in reports.items():
        table.add_row(
            name, str(report["relations"]), str(report["supp"]), f"{100 * report['supp_recall']:.1f} %",
            f"{100 * report['not_supp_recall']:.1f} %", f"{report['expected_calibration_error']:.3f}",
        )  # fmt: skip
    return table


ISETS_FROM_HELP = (
    "How ISets are drawn: random: random detected boxes; neighbours: a detected box and its nearest neighbours; "
    "mixed: each ISet one or the other at even odds."
)
FEATURES_HELP = (
    "paper: the 19 numbers of Eq. 6; extended: those and 17 contact features (gaps, overlaps, cloud); "
    "general: 15 features of the two boxes' poses (oriented footprints, gaps, tilt, separation), no cloud."
)


def _examples(
    data_dirs: str | tuple[str, ...],
    r: int,
    isets: int,
    seed: int,
    jobs: int,
    settings: Any,
    draw: str = "random",
    vary_clouds: bool = False,
    pose_noise: float = 0.0,
) -> Any:
    """:func:`unstack.learning.training.pooled_examples` with a progress bar."""
    from unstack.cli.progress import progress_bar
    from unstack.dataset_folders import require_configurations
    from unstack.learning.training import pooled_examples

    folders = (data_dirs,) if isinstance(data_dirs, str) else data_dirs
    piles = sum(len(require_configurations(folder)) for folder in folders)  # before any bar: the error alone
    with progress_bar("features: piles") as report:
        report(0, piles)  # the count is known before the first pile ends
        return pooled_examples(
            folders, r=r, isets=isets, seed=seed, settings=settings, n_jobs=jobs, draw=draw,
            vary_clouds=vary_clouds, pose_noise=pose_noise, progress=report,
        )  # fmt: skip


def _files_in(folder: str) -> list[Path]:
    """The files of a data set in its folder: the manifest and the configurations' scenes and
    clouds (none when it is no folder: the folder is checked later)."""
    from unstack.dataset_folders import MANIFEST

    if not Path(folder).is_dir():
        return []
    return [path for path in Path(folder).iterdir() if path.name.startswith("config-") or path.name == MANIFEST]


@click.command()
@click.argument("data_dirs", nargs=-1, required=True, type=click.Path(file_okay=False))
@click.option("-o", "--output", required=True, type=click.Path(dir_okay=False), help="Model file to write.")
@click.option("--learner", type=click.Choice(list(LEARNERS)), default="svm",
              show_default=True, help="svm: RBF SVM with LIBSVM probabilities (the paper).")  # fmt: skip
@click.option("--r", "r", type=click.IntRange(min=2), default=5, show_default=True, help="Boxes per ISet.")
@click.option("--isets", type=click.IntRange(min=1), default=3, show_default=True, help="ISets per configuration.")
@click.option("--isets-from", "draw", type=click.Choice(list(ISET_DRAWS)), default="random",
              show_default=True, help=ISETS_FROM_HELP)  # fmt: skip
@click.option("--vary-clouds/--same-clouds", default=False, show_default=True,
              help="Show each ISet its cloud as another sensor might: sparser, noisier, with holes.")  # fmt: skip
@click.option("--pose-noise", type=constrained(dataset_examples, "pose_noise"), default=0.0, show_default=True,
              help="Show each ISet its boxes as a detector reports them: errors of this many m (0-0.1).")  # fmt: skip
@click.option("--seed", type=Checked(int, functools.partial(LEARNING_SEED.check, name="seed")), default=0,
              show_default=True, help="Seed of the ISets, the split and the folds (0 to 2**32 - 1).")  # fmt: skip
@click.option("--split-by", type=click.Choice(list(SPLITS)), default="pairs", show_default=True,
              help="pairs: the paper's split of the relations; configuration: whole piles on one side.")  # fmt: skip
@click.option("--cv", type=int, default=10, show_default=True,
              help="Cross-validation folds on the training part (2-1,000; fewer where the rarer class or the piles "
              "are fewer).")  # fmt: skip
@click.option("--validation-size", type=float, default=0.3, show_default=True,
              help="Share held out for validation (0 to below 1; 0: none held out, no hold-out figures).")  # fmt: skip
@click.option("--features", "feature_set", type=click.Choice(list(FEATURE_SETS)), default="paper",
              show_default=True, help=FEATURES_HELP)  # fmt: skip
@click.option("--offset", type=float, default=1.0, show_default=True,
              help="d: interest-point offset (m; above 0, at most 10).")  # fmt: skip
@click.option("--sigma", type=float, default=0.5, show_default=True,
              help="Width of the DBAF's Gaussian (m; above 0, at most 10).")  # fmt: skip
@click.option("--jobs", type=click.IntRange(1, MAX_JOBS), default=1, show_default=True, help="Parallel processes.")
@click.option("--json", "as_json", is_flag=True, help="Print the training report as JSON.")
def train(
    data_dirs: tuple[str, ...],
    output: str,
    learner: str,
    r: int,
    isets: int,
    draw: str,
    vary_clouds: bool,
    pose_noise: float,
    seed: int,
    split_by: str,
    cv: int,
    validation_size: float,
    feature_set: str,
    offset: float,
    sigma: float,
    jobs: int,
    as_json: bool,
) -> None:
    """Train the support classifier on simulated data sets (unstack simulate) and save it.

    Several DATA_DIRS (pile families, say) are pooled; their piles stay whole in the split.
    """
    from unstack.atomic import check_output_path
    from unstack.learning.features import FeatureSettings
    from unstack.learning.model_file import save_model
    from unstack.learning.training import train_support_model, training_provenance

    if not 2 <= cv <= MAX_FOLDS:
        raise UnstackError(f"--cv: expected 2 to {MAX_FOLDS:,} cross-validation folds, got {cv}")
    if not 0.0 <= validation_size < 1.0:  # NaN too
        raise UnstackError(f"--validation-size: expected a share from 0 up to (not including) 1, got {validation_size}")
    if Path(output).suffix.lower() != ".skops":
        raise UnstackError(f"-o: expected a model file name ending in .skops, got {output!r}")
    resolved = [os.path.realpath(folder) for folder in data_dirs]
    repeated = next(
        (folder for folder, real in zip(data_dirs, resolved, strict=True) if resolved.count(real) > 1), None
    )
    if repeated is not None:
        raise UnstackError(f"{repeated}: the data set is given twice (each pile would count twice)")
    check_output_path(output, inputs=[path for folder in data_dirs for path in _files_in(folder)])
    from unstack.learning.model_file import default_model_path

    shipped = default_model_path().parent.resolve()
    if Path(output).resolve().parent == shipped:
        raise UnstackError(
            f"{output}: cannot write there: the folder of the models shipped with unstack ({shipped}); "
            "choose another file and pass it with --model"
        )
    settings = FeatureSettings(offset=offset, sigma=sigma, feature_set=feature_set)
    examples = _examples(data_dirs, r, isets, seed, jobs, settings, draw, vary_clouds, pose_noise)
    console = Console(stderr=as_json)
    held_out = f"hold-out figures on {validation_size:.0%}, then " if validation_size > 0 else ""
    console.print(
        f"{len(examples.labels)} relations ({int(examples.labels.sum())} SUPP) from "
        f"{counted(len(set(examples.configuration.tolist())), 'configuration')}; {held_out}cross-validating {learner} "
        f"({cv} folds at most) on all of them ..."
    )
    provenance = training_provenance(
        data_dirs, examples, vary_clouds=vary_clouds, pose_noise=pose_noise, seed=seed, r=r,
        isets_per_configuration=isets, isets_from=draw,
    )  # fmt: skip
    from unstack.cli.progress import still_working

    with still_working("cross-validating"):
        run = train_support_model(
            examples, settings, learner=learner, cv=cv, validation_size=validation_size, split_by=split_by,
            seed=seed, n_jobs=jobs, provenance=provenance,
        )  # fmt: skip
    model = run.model
    save_model(model, output)
    for warning in run.warnings:
        click.echo(f"unstack: warning: {warning}", err=True)
    validation = model.metadata["validation"]
    report = {"model": output, "learner": learner, "features": settings.to_dict(),
              **{k: model.metadata[k] for k in ("best_params", "cv_score")},
              "validation": validation, "training": {k: v for k, v in model.metadata["training"].items()
              if k != "simulation_settings"}}  # fmt: skip
    if as_json:
        click.echo(report_text(report), nl=False)
        return
    best = model.metadata["best_params"]
    params = ", ".join(f"{key.rsplit('__', 1)[-1]} = {value:g}" for key, value in best.items())
    score = model.metadata["cv_score"]
    console.print(
        Text.assemble(("chosen: ", "bold"), params, f"  (cross-validated balanced accuracy {score:.3f}; 0.5 is chance)")
    )
    if validation:
        console.print(metrics_view(validation, "hold-out confusion matrix (Fig. 5 layout)"))
        if "by_data_set" in validation:
            console.print(data_sets_view(validation["by_data_set"]))
        console.print("(of a model fitted on the rest; the saved model is fitted on all relations)")
    console.print(f"model written to {output}")


@click.command()
@click.argument("model_file", type=str)
@data_dir_argument
@click.option("--r", "r", type=click.IntRange(min=2), default=5, show_default=True, help="Boxes per ISet.")
@click.option("--isets", type=click.IntRange(min=1), default=3, show_default=True, help="ISets per configuration.")
@click.option("--isets-from", "draw", type=click.Choice(list(ISET_DRAWS)), default="random",
              show_default=True, help=ISETS_FROM_HELP)  # fmt: skip
@click.option("--pose-noise", type=constrained(dataset_examples, "pose_noise"), default=0.0, show_default=True,
              help="Score on boxes as a detector reports them: errors of this many metres (0 to 0.1).")  # fmt: skip
@click.option("--seed", type=click.IntRange(min=0), default=1, show_default=True, help="Seed of the ISets.")
@click.option("--jobs", type=click.IntRange(1, MAX_JOBS), default=1, show_default=True, help="Parallel processes.")
@click.option("--json", "as_json", is_flag=True, help="Print the report as JSON.")
@click.option(
    "--reliability", type=click.Path(dir_okay=False), default=None, help="Write a reliability diagram (.png or .svg)."
)
def evaluate(
    model_file: str,
    data_dir: str,
    r: int,
    isets: int,
    draw: str,
    pose_noise: float,
    seed: int,
    jobs: int,
    as_json: bool,
    reliability: str | None,
) -> None:
    """Score a model (a file or a shipped model's name) on a data set: confusion matrix,
    success rate, BER, entropy, calibration."""
    from unstack.experiments.fig5a import paper_point
    from unstack.learning.metrics import classification_report, one_class_warning, save_reliability_diagram
    from unstack.learning.model_file import data_set_out_of_distribution

    if r < 2 or isets < 1 or jobs < 1:
        raise UnstackError("expected --r >= 2, --isets >= 1 and --jobs >= 1")
    if reliability:  # before the work: a picture matplotlib cannot write fails after it
        from unstack.atomic import check_output_path

        if Path(reliability).suffix.lower() not in (".png", ".svg"):
            raise UnstackError(f"--reliability: {reliability}: expected a .png or .svg file")
        check_output_path(reliability)
    model, _ = load_support_model(model_file)
    examples = _examples(data_dir, r, isets, seed, jobs, model.features, draw, pose_noise=pose_noise)
    probability = model.support_probability(examples.features)
    report = classification_report(examples.labels, probability)
    report["fig5a"] = paper_point(examples.labels, probability)
    report["out_of_range"] = model.out_of_range_summary(examples.features)
    doubt = data_set_out_of_distribution(report["out_of_range"], len(examples.features), data_dir)
    if doubt:
        click.echo(f"unstack: warning: {doubt}", err=True)
    one_class = one_class_warning(report, data_dir)
    if one_class:
        click.echo(f"unstack: warning: {one_class}", err=True)
        report["balanced_error_rate"] = None  # Eq. 16 averages the two classes' error rates
    if reliability:
        save_reliability_diagram(report, reliability, title=f"{model_file} on {data_dir}")
    if as_json:
        click.echo(report_text({"model": model_file, "data": data_dir, **report}), nl=False)
        return
    console = Console()
    console.print(metrics_view(report, f"{model_file} on {data_dir}: confusion matrix (Fig. 5 layout)"))
    point = report["fig5a"]
    if not one_class:
        console.print(
            f"ROC AUC {point['auc']:.3f}; at the paper's SUPP recall ({100 * point['supp_recall']:.1f} %) "
            f"the best not-SUPP recall is {100 * point['not_supp_recall']:.1f} % "
            f"(paper: {100 * point['paper_not_supp_recall']:.1f} %)"
        )
    console.print(
        f"relations with a feature outside the model's training range: {report['out_of_range']['rows']:,} of "
        f"{len(examples.features):,} ({100 * report['out_of_range']['share']:.1f} %)"
    )


@click.command()
@click.argument("scene_file", type=str)
@model_path_option
@click.option("-o", "--output", type=click.Path(dir_okay=False), default=None, help="Write the JSON here (atomically).")
@click.option("--statics/--no-statics", default=True, show_default=True, help=STATICS_HELP)
def probabilities(scene_file: str, model_path: str | None, output: str | None, statics: bool) -> None:
    """Support probabilities of a scene's detected boxes, as unstack.supports/1 JSON."""
    from unstack.atomic import atomic_write_text, check_output_path
    from unstack.jsonio import document_text
    from unstack.scene import load_scene

    if output:
        check_output_path(output, inputs=[scene_file])
    supports = scene_supports(load_scene(scene_file), model_path, statics)
    for line in supports.metadata.get("warnings", []):
        click.echo(f"unstack: warning: {line}", err=True)
    text = document_text(supports.to_dict(), output or "standard output")
    if output:
        atomic_write_text(output, text)
    else:
        click.echo(text, nl=False)
