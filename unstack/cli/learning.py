"""``unstack train``, ``unstack evaluate``, ``unstack probabilities``: the learned support model."""

from __future__ import annotations

import json
from typing import Any

import click
from rich.console import Console, Group
from rich.table import Table
from rich.text import Text

from unstack.errors import UnstackError
from unstack.learning.features import FEATURE_SETS
from unstack.learning.training_data import ISET_DRAWS

__all__ = ["evaluate", "load_support_model", "metrics_view", "probabilities", "scene_supports", "train"]


def load_support_model(path: str | None) -> tuple[Any, str]:
    """The model of ``--model`` and its name (:func:`unstack.api.load_model`: a file, a shipped
    model's name, or the default model when None)."""
    from unstack.cli.main import load_model_option

    return load_model_option(path)


def scene_supports(scene: Any, model_path: str | None) -> Any:
    """Support probabilities of a scene's detected boxes (:func:`unstack.support_probabilities`)."""
    from unstack.api import support_probabilities

    return support_probabilities(scene, model_path)


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
        summary.add_row(label, f"{value:.4f}" if isinstance(value, float) else str(value))
    return Group(confusion, summary)


ISETS_FROM_HELP = "How ISets are drawn: random detected boxes, or a detected box and its nearest neighbours."
MODEL_HELP = (
    "Model file, or a shipped model: general (the default: pose features, five pile families), paper (the "
    "paper's SVM, for the reproduction) or extended (the paper's piles with contact features)."
)
FEATURES_HELP = (
    "paper: the 19 numbers of Eq. 6; extended: those and 17 contact features (gaps, overlaps, cloud); "
    "general: 15 features of the two boxes' poses (oriented footprints, gaps, tilt, separation), no cloud."
)
#: Configuration numbers of the n-th data set of a training run start at n times this.
CONFIGURATION_OFFSET = 100_000


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
    from dataclasses import replace

    from unstack.learning.training_data import SupportExamples, dataset_examples
    from unstack.sim.dataset import require_configurations

    folders = (data_dirs,) if isinstance(data_dirs, str) else data_dirs
    for folder in folders:
        require_configurations(folder)  # before any progress bar: the error is the only line
    from unstack.cli.progress import progress_bar

    parts = []
    for number, folder in enumerate(folders):
        with progress_bar(f"features {folder}" if len(folders) > 1 else "features") as report:
            part = dataset_examples(folder, r=r, isets=isets, seed=seed + number, settings=settings, n_jobs=jobs,
                                    progress=report, draw=draw, vary_clouds=vary_clouds,
                                    pose_noise=pose_noise)  # fmt: skip
        parts.append(replace(part, configuration=part.configuration + number * CONFIGURATION_OFFSET))
    examples = SupportExamples.concatenate(parts)
    if len(examples.labels) == 0:
        raise UnstackError(f"{', '.join(folders)}: no ISet of at least 2 detected boxes; nothing to learn from")
    return examples


@click.command()
@click.argument("data_dirs", nargs=-1, required=True, type=click.Path(file_okay=False))
@click.option("-o", "--output", required=True, type=click.Path(dir_okay=False), help="Model file to write.")
@click.option("--learner", type=click.Choice(["svm", "gradient_boosting", "calibrated_svm"]), default="svm",
              show_default=True, help="svm: RBF SVM with LIBSVM probabilities (the paper).")  # fmt: skip
@click.option("--r", "r", type=int, default=5, show_default=True, help="Boxes per ISet.")
@click.option("--isets", type=int, default=3, show_default=True, help="ISets drawn per configuration.")
@click.option("--isets-from", "draw", type=click.Choice(list(ISET_DRAWS)), default="random",
              show_default=True, help=ISETS_FROM_HELP)  # fmt: skip
@click.option("--vary-clouds/--same-clouds", default=False, show_default=True,
              help="Show each ISet its cloud as another sensor might: sparser, noisier, with holes.")  # fmt: skip
@click.option("--pose-noise", type=click.FloatRange(0.0, 0.1), default=0.0, show_default=True,
              help="Show each ISet its boxes as a detector reports them: errors of this many metres.")  # fmt: skip
@click.option("--seed", type=int, default=0, show_default=True, help="Seed of the ISets, the split and the folds.")
@click.option("--split-by", type=click.Choice(["pairs", "configuration"]), default="pairs", show_default=True,
              help="pairs: the paper's split of the relations; configuration: whole piles on one side.")  # fmt: skip
@click.option("--cv", type=int, default=10, show_default=True, help="Cross-validation folds on the training part.")
@click.option("--validation-size", type=float, default=0.3, show_default=True, help="Share held out for validation.")
@click.option("--features", "feature_set", type=click.Choice(list(FEATURE_SETS)), default="paper",
              show_default=True, help=FEATURES_HELP)  # fmt: skip
@click.option("--offset", type=float, default=1.0, show_default=True, help="d: interest-point offset (m).")
@click.option("--sigma", type=float, default=0.5, show_default=True, help="Width of the DBAF's Gaussian (m).")
@click.option("--jobs", type=int, default=1, show_default=True, help="Parallel processes.")
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
    from unstack.learning.classifier import SupportClassifier
    from unstack.learning.features import FeatureSettings
    from unstack.learning.model_file import SupportModel, save_model
    from unstack.learning.training_data import dataset_fingerprint
    from unstack.sim.dataset import read_manifest

    if r < 2 or isets < 1 or cv < 2 or jobs < 1 or not 0.0 <= validation_size < 1.0:
        raise UnstackError("expected --r >= 2, --isets >= 1, --cv >= 2, --jobs >= 1 and 0 <= --validation-size < 1")
    settings = FeatureSettings(offset=offset, sigma=sigma, feature_set=feature_set)
    examples = _examples(data_dirs, r, isets, seed, jobs, settings, draw, vary_clouds, pose_noise)
    console = Console(stderr=as_json)
    console.print(
        f"{len(examples.labels)} relations ({int(examples.labels.sum())} SUPP) from "
        f"{len(set(examples.configuration.tolist()))} configurations; cross-validating {learner} ({cv} folds) ..."
    )
    classifier = SupportClassifier(
        learner=learner, cv=cv, validation_size=validation_size, n_jobs=jobs, random_state=seed
    ).fit(examples.features, examples.labels, groups=examples.configuration if split_by == "configuration" else None)
    manifests = [read_manifest(folder) or {} for folder in data_dirs]
    single = len(data_dirs) == 1
    training = {
        "data": str(data_dirs[0]) if single else [str(folder) for folder in data_dirs],
        "fingerprint": dataset_fingerprint(data_dirs[0]) if single else [dataset_fingerprint(f) for f in data_dirs],
        "simulation_seed": manifests[0].get("seed") if single else [m.get("seed") for m in manifests],
        "simulation_settings": manifests[0].get("settings") if single else [m.get("settings") for m in manifests],
        "vary_clouds": vary_clouds,
        "pose_noise": pose_noise,
        "seed": seed,
        "r": r,
        "isets_per_configuration": isets,
        "isets_from": draw,
        "split_by": split_by,
        "relations": len(examples.labels),
        "supp": int(examples.labels.sum()),
        "validation_size": validation_size,
    }
    model = SupportModel.from_classifier(classifier, settings, training=training, training_features=examples.features)
    save_model(model, output)
    report = {"model": output, "learner": learner, "features": settings.to_dict(),
              **{k: model.metadata[k] for k in ("best_params", "cv_score")},
              "validation": classifier.validation_metrics_, "training": {k: v for k, v in training.items()
              if k != "simulation_settings"}}  # fmt: skip
    if as_json:
        click.echo(json.dumps(report, indent=2))
        return
    params = ", ".join(f"{key.rsplit('__', 1)[-1]} = {value:g}" for key, value in classifier.best_params_.items())
    console.print(Text.assemble(("chosen: ", "bold"), params, f"  (cross-validated score {classifier.cv_score_:.3f})"))
    if classifier.validation_metrics_:
        console.print(metrics_view(classifier.validation_metrics_, "validation confusion matrix (Fig. 5 layout)"))
    console.print(f"model written to {output}")


@click.command()
@click.argument("model_file", type=str)
@click.argument("data_dir", type=click.Path(file_okay=False))
@click.option("--r", "r", type=int, default=5, show_default=True, help="Boxes per ISet.")
@click.option("--isets", type=int, default=3, show_default=True, help="ISets drawn per configuration.")
@click.option("--isets-from", "draw", type=click.Choice(list(ISET_DRAWS)), default="random",
              show_default=True, help=ISETS_FROM_HELP)  # fmt: skip
@click.option("--pose-noise", type=click.FloatRange(0.0, 0.1), default=0.0, show_default=True,
              help="Score on boxes as a detector reports them: errors of this many metres.")  # fmt: skip
@click.option("--seed", type=int, default=1, show_default=True, help="Seed of the ISets.")
@click.option("--jobs", type=int, default=1, show_default=True, help="Parallel processes.")
@click.option("--json", "as_json", is_flag=True, help="Print the report as JSON.")
@click.option("--reliability", type=click.Path(dir_okay=False), default=None, help="Write a reliability diagram PNG.")
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
    from unstack.learning.metrics import classification_report, save_reliability_diagram

    if r < 2 or isets < 1 or jobs < 1:
        raise UnstackError("expected --r >= 2, --isets >= 1 and --jobs >= 1")
    model, _ = load_support_model(model_file)
    examples = _examples(data_dir, r, isets, seed, jobs, model.features, draw, pose_noise=pose_noise)
    report = classification_report(examples.labels, model.support_probability(examples.features))
    if reliability:
        save_reliability_diagram(report, reliability, title=f"{model_file} on {data_dir}")
    if as_json:
        click.echo(json.dumps({"model": model_file, "data": data_dir, **report}, indent=2))
        return
    Console().print(metrics_view(report, f"{model_file} on {data_dir}: confusion matrix (Fig. 5 layout)"))


@click.command()
@click.argument("scene_file", type=str)
@click.option("--model", "model_path", default=None, help=MODEL_HELP)
@click.option("-o", "--output", type=click.Path(dir_okay=False), default=None, help="Write the JSON here (atomically).")
def probabilities(scene_file: str, model_path: str | None, output: str | None) -> None:
    """Support probabilities of a scene's detected boxes, as unstack.supports/1 JSON."""
    from unstack.atomic import atomic_write_text
    from unstack.scene import load_scene

    supports = scene_supports(load_scene(scene_file), model_path)
    for line in supports.metadata.get("warnings", []):
        click.echo(f"unstack: warning: {line}", err=True)
    text = json.dumps(supports.to_dict(), indent=2) + "\n"
    if output:
        atomic_write_text(output, text)
    else:
        click.echo(text, nl=False)
