"""Model files: round trip, and a one-line error for anything that is not a model we trust."""

from __future__ import annotations

import json
import os
import zipfile
from pathlib import Path

import numpy as np
import pytest
import skops.io

from unstack.learning.classifier import SupportClassifier
from unstack.learning.features import FeatureSettings
from unstack.learning.model_file import MODEL_FORMAT, InvalidModel, SupportModel, load_model, save_model

GRID = {"svc__estimator__C": [1.0], "svc__estimator__gamma": [0.1]}


@pytest.fixture(scope="module")
def fitted() -> tuple[SupportClassifier, np.ndarray]:
    rng = np.random.default_rng(1)
    features = rng.normal(size=(120, 19))
    labels = (features[:, 0] > 0.3).astype(int)
    return SupportClassifier(cv=3, param_grid=GRID, random_state=0).fit(features, labels), features


@pytest.mark.slow
@pytest.mark.parametrize("learner", ["svm", "gradient_boosting", "calibrated_svm"])
def test_round_trip(tmp_path: Path, learner: str) -> None:
    rng = np.random.default_rng(2)
    features = rng.normal(size=(120, 19))
    labels = (features[:, 0] > 0.3).astype(int)
    grid = {"gb__max_leaf_nodes": [7]} if learner == "gradient_boosting" else GRID
    classifier = SupportClassifier(learner=learner, cv=3, param_grid=grid, random_state=0).fit(features, labels)
    settings = FeatureSettings(offset=0.8, sigma=0.4)
    held_out = {"relations": 36, "supp_recall": 0.9}
    wrapped = SupportModel.from_classifier(classifier, settings, training={"seed": 7}, validation=held_out)
    save_model(wrapped, tmp_path / "m.skops")
    model = load_model(tmp_path / "m.skops")
    assert model.features == settings
    assert model.metadata["learner"] == learner and model.metadata["training"] == {"seed": 7}
    assert model.metadata["validation"] == held_out
    assert np.array_equal(model.support_probability(features), classifier.predict_proba(features)[:, 1])


def write_payload(path: Path, payload: object) -> Path:
    path.write_bytes(skops.io.dumps(payload))
    return path


def test_bad_files_are_one_line_errors(tmp_path: Path, fitted: tuple[SupportClassifier, np.ndarray]) -> None:
    classifier, _ = fitted
    text = tmp_path / "notes.skops"
    text.write_text("hello")
    archive = tmp_path / "other.zip"
    with zipfile.ZipFile(archive, "w") as handle:
        handle.writestr("a.txt", "x")
    metadata = json.dumps({"features": FeatureSettings().to_dict()})
    cases = {
        text: r"\$: expected an unstack model file \(a skops file\), got something else",
        archive: r"\$: expected an unstack model file \(a skops file\)",
        tmp_path: r"\$: expected a model file, got a directory",
        tmp_path / "missing.skops": r"\$: cannot read the model file",
        write_payload(tmp_path / "list.skops", [1, 2]): r"expected an unstack model \(a dict with 'format'\)",
        write_payload(
            tmp_path / "v9.skops",
            {"format": "unstack.model/9", "metadata": metadata, "estimator": classifier.estimator_},
        ): r"\$.format: unsupported model format 'unstack.model/9'",
        write_payload(
            tmp_path / "nometa.skops", {"format": MODEL_FORMAT, "estimator": classifier.estimator_}
        ): r"\$: expected the keys format, metadata, estimator; missing: metadata",
    }
    for path, message in cases.items():
        with pytest.raises(InvalidModel, match=message) as caught:
            load_model(path)
        assert "\n" not in str(caught.value)


GOOD_METADATA = {"features": FeatureSettings().to_dict()}


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"metadata": json.dumps("hello")}, r"\$\.metadata: expected a JSON object, got a string"),
        ({"metadata": "null"}, r"\$\.metadata: expected a JSON object, got null"),
        ({"metadata": "[" * 100_000 + "]" * 100_000}, r"\$\.metadata: expected JSON nested at most 64 levels deep"),
        ({"metadata": json.dumps({**GOOD_METADATA, "x": [[[[[[[[[[0]]]]]]]]]] * 7})}, None),  # 10 deep: read
        ({"format": np.array([MODEL_FORMAT])}, r"\$\.format: unsupported model format array"),
        ({"padding": np.zeros(8)}, r"\$: expected the keys format, metadata, estimator; unknown: padding"),
        (
            {"metadata": json.dumps({"features": {**FeatureSettings().to_dict(), "offset": True}})},
            r"\$\.metadata\.features\.offset: expected a finite number, got True",
        ),
        (
            {"metadata": json.dumps({"features": {**FeatureSettings().to_dict(), "sigma": -1}})},
            r"\$\.metadata\.features: feature settings need 0 < sigma",
        ),
    ],
    ids=["text", "null", "deep", "shallow", "format-array", "unknown-key", "bool-offset", "negative-sigma"],
)
def test_a_payload_at_odds_with_the_model_format_is_refused_by_path(
    tmp_path: Path, fitted: tuple[SupportClassifier, np.ndarray], change: dict[str, object], message: str | None
) -> None:
    classifier, _ = fitted
    payload = {"format": MODEL_FORMAT, "metadata": json.dumps(GOOD_METADATA), "estimator": classifier.estimator_}
    path = write_payload(tmp_path / "model.skops", {**payload, **change})
    if message is None:
        assert load_model(path).features == FeatureSettings()
        return
    with pytest.raises(InvalidModel, match=message):
        load_model(path)


@pytest.mark.parametrize(
    "bounds", [[0.0, "1"], [False, True], {"lo": 0, "hi": 1}, [1.0, 0.0], [0.0, 1.0, 2.0], [float("nan"), 1.0]]
)
def test_feature_ranges_of_no_two_ordered_numbers_are_refused(
    tmp_path: Path, fitted: tuple[SupportClassifier, np.ndarray], bounds: object
) -> None:
    from unstack.learning.features import feature_names

    classifier, _ = fitted
    names = feature_names(FeatureSettings())
    ranges = {name: [0.0, 1.0] for name in names} | {names[3]: bounds}
    metadata = json.dumps({**GOOD_METADATA, "feature_ranges": ranges})
    path = write_payload(
        tmp_path / "m.skops", {"format": MODEL_FORMAT, "metadata": metadata, "estimator": classifier.estimator_}
    )
    with pytest.raises(InvalidModel, match=rf"\$\.metadata\.feature_ranges\.{names[3]}: expected \[low, high\]"):
        load_model(path)


def test_a_small_file_that_unpacks_to_more_than_a_model_may_hold_is_refused_unread(
    tmp_path: Path, fitted: tuple[SupportClassifier, np.ndarray], monkeypatch: pytest.MonkeyPatch
) -> None:
    from unstack.learning import model_file

    classifier, _ = fitted
    payload = {"format": MODEL_FORMAT, "metadata": json.dumps(GOOD_METADATA), "estimator": classifier.estimator_}
    path = tmp_path / "m.skops"
    path.write_bytes(skops.io.dumps(payload, compression=zipfile.ZIP_DEFLATED, compresslevel=9))
    unpacked = sum(member.file_size for member in zipfile.ZipFile(path).infolist())
    monkeypatch.setattr(model_file, "MAX_MODEL_BYTES", unpacked - 1)  # a limit this file passes by one byte
    with pytest.raises(InvalidModel, match=r"\$: expected a model of at most 0 MiB, this one unpacks to"):
        load_model(path)
    monkeypatch.setattr(model_file, "MAX_MODEL_BYTES", unpacked)
    assert load_model(path).features == FeatureSettings()


def test_a_three_class_estimator_is_no_support_model(tmp_path: Path) -> None:
    from sklearn.linear_model import LogisticRegression

    rng = np.random.default_rng(3)
    three = LogisticRegression().fit(rng.normal(size=(60, 19)), np.arange(60) % 3)
    path = write_payload(
        tmp_path / "m.skops", {"format": MODEL_FORMAT, "metadata": json.dumps(GOOD_METADATA), "estimator": three}
    )
    with pytest.raises(InvalidModel, match=r"\$\.estimator: expected the classes 0 and 1 \(1: supports\), got 0, 1, 2"):
        load_model(path)


def test_a_file_with_untrusted_types_is_refused_naming_them(tmp_path: Path) -> None:
    from sklearn.preprocessing import FunctionTransformer

    payload = {"format": MODEL_FORMAT, "metadata": "{}", "estimator": FunctionTransformer(func=os.system)}
    path = write_payload(tmp_path / "evil.skops", payload)
    with pytest.raises(InvalidModel, match=r"refusing to load types that are not trusted: posix.system"):
        load_model(path)


def test_the_shipped_default_model_is_the_general_one_with_its_feature_ranges() -> None:
    from unstack.learning.model_file import default_model_path

    model = load_model(default_model_path())
    assert model.metadata["learner"] == "gradient_boosting" and model.features.feature_set == "general"
    assert model.metadata["training"]["split_by"] == "configuration" and model.metadata["training"]["pose_noise"] > 0
    assert len(model.metadata["feature_ranges"]) == 15
    validation = model.metadata["validation"]
    assert validation["relations"] > 500 and 0 <= validation["balanced_error_rate"] <= 0.5


def test_the_shipped_paper_model_is_the_papers_svm() -> None:
    from unstack.learning.model_file import bundled_model_path

    model = load_model(bundled_model_path("paper"))
    assert model.metadata["learner"] == "svm" and model.features == FeatureSettings()


def test_the_shipped_extended_model_loads_and_was_split_by_pile() -> None:
    from unstack.learning.model_file import bundled_model_path

    model = load_model(bundled_model_path("extended"))
    assert model.metadata["learner"] == "gradient_boosting"
    assert model.features == FeatureSettings(feature_set="extended")
    assert model.metadata["training"]["split_by"] == "configuration"
    rows = np.random.default_rng(0).normal(size=(3, 36))
    assert model.support_probability(rows).shape == (3,)


def openmp_threads() -> list[int]:
    from threadpoolctl import threadpool_info

    return [info["num_threads"] for info in threadpool_info() if info["user_api"] == "openmp"]


def test_a_prediction_runs_on_the_calling_thread_alone_and_restores_its_openmp_limit() -> None:
    from sklearn.ensemble import HistGradientBoostingClassifier  # loads scikit-learn's OpenMP runtime
    from sklearn.linear_model import LogisticRegression
    from threadpoolctl import threadpool_limits

    class ThreadRecordingClassifier(LogisticRegression):
        """A real classifier that notes the OpenMP limits in force while it predicts."""

        def predict_proba(self, features: np.ndarray) -> np.ndarray:  # type: ignore[override]
            self.threads_seen_ = openmp_threads()
            return super().predict_proba(features)

    rng = np.random.default_rng(3)
    features = rng.normal(size=(60, 19))
    labels = (features[:, 0] > 0).astype(int)
    estimator = ThreadRecordingClassifier().fit(features, labels)
    model = SupportModel(estimator=estimator, features=FeatureSettings(), metadata={})
    with threadpool_limits(limits=2, user_api="openmp"):  # the tests run with OMP_NUM_THREADS=1
        before = openmp_threads()
        probabilities = model.support_probability(features)
        after = openmp_threads()
    assert before == [2] * len(before) and before, f"no OpenMP runtime ({HistGradientBoostingClassifier.__name__})"
    assert estimator.threads_seen_ == [1] * len(before)
    assert after == before
    assert np.array_equal(probabilities, LogisticRegression().fit(features, labels).predict_proba(features)[:, 1])


_LATE_RUNTIME = """
import numpy as np
from sklearn.linear_model import LogisticRegression
from threadpoolctl import threadpool_info, threadpool_limits

from unstack.learning.features import FeatureSettings
from unstack.learning.model_file import SupportModel

def openmp_threads():
    return [info["num_threads"] for info in threadpool_info() if info["user_api"] == "openmp"]

class Recording(LogisticRegression):
    def predict_proba(self, features):
        self.threads_seen_ = openmp_threads()
        return super().predict_proba(features)

rows = np.random.default_rng(3).normal(size=(40, 19))
estimator = Recording().fit(rows, (rows[:, 0] > 0).astype(int))
model = SupportModel(estimator=estimator, features=FeatureSettings(), metadata={})
model.support_probability(rows)  # the thread pools found with scikit-learn's runtime alone
from numba.np.ufunc import omppool  # noqa: F401  (loads the system's OpenMP runtime: a second one)
with threadpool_limits(limits=2, user_api="openmp"):
    model.support_probability(rows)
print(len(openmp_threads()), estimator.threads_seen_)
"""


def test_a_runtime_loaded_after_the_first_prediction_is_limited_too() -> None:
    import subprocess
    import sys

    result = subprocess.run([sys.executable, "-c", _LATE_RUNTIME], capture_output=True, text=True, check=True)
    runtimes, seen = result.stdout.strip().split(" ", 1)
    assert int(runtimes) == 2, result.stdout
    assert seen == "[1, 1]"


def _unusable_models() -> dict[str, tuple[object, dict[str, object] | None]]:
    """Classifiers that load but cannot give P(SUPP) for the 19 paper features (name: estimator, metadata)."""
    from sklearn.linear_model import LogisticRegression

    rng = np.random.default_rng(5)
    rows, labels = rng.normal(size=(40, 19)), np.r_[np.zeros(20), np.ones(20)].astype(int)
    nan_coefficients = LogisticRegression().fit(rows, labels)
    nan_coefficients.coef_[:] = np.nan
    return {
        "never fitted": (LogisticRegression(), None),
        "three features": (LogisticRegression().fit(rows[:, :3], labels), None),
        "classes 0 and 2": (LogisticRegression().fit(rows, 2 * labels), None),
        "predicts NaN": (nan_coefficients, None),
        "ranges of other features": (LogisticRegression().fit(rows, labels), {"feature_ranges": {"bogus": [0, 1]}}),
    }


@pytest.mark.parametrize(
    ("case", "message"),
    [
        ("never fitted", r"\$.estimator: expected a fitted classifier, got one that was never fitted"),
        ("three features", r"\$.estimator: expected a classifier of the 19 paper features, got one of 3"),
        ("classes 0 and 2", r"\$.estimator: expected the classes 0 and 1 \(1: supports\), got 0, 2"),
        ("predicts NaN", r"\$.estimator: expected probabilities in \[0, 1\], the model gave nan"),
        ("ranges of other features", r"\$.metadata.feature_ranges: expected a \[low, high\] range for each of: "),
    ],
)
def test_a_model_that_loads_but_cannot_predict_is_refused_in_one_line(tmp_path: Path, case: str, message: str) -> None:
    estimator, metadata = _unusable_models()[case]
    path = tmp_path / "model.skops"
    save_model(SupportModel(estimator, FeatureSettings(), metadata or {}), path)
    with pytest.raises(InvalidModel, match=message) as caught:
        load_model(path)
    assert str(caught.value).startswith(str(path)) and "\n" not in str(caught.value)


@pytest.mark.parametrize("shift, warned", [(0.0, False), (6.0, True)])
def test_a_data_set_is_out_of_distribution_when_over_a_tenth_of_its_relations_leave_the_range(
    fitted: tuple[SupportClassifier, np.ndarray], shift: float, warned: bool
) -> None:
    from unstack.learning.features import feature_names
    from unstack.learning.model_file import DATA_SET_OUT_OF_RANGE, data_set_out_of_distribution

    classifier, _ = fitted
    settings = FeatureSettings()
    rng = np.random.default_rng(2)
    training = rng.normal(size=(5000, 19))  # the ranges of a training set of the usual size
    model = SupportModel.from_classifier(classifier, settings, training={}, training_features=training)
    data = rng.normal(size=(400, 19))
    data[:, 3] += shift  # one feature moved by six standard deviations
    summary = model.out_of_range_summary(data)
    assert (summary["share"] > DATA_SET_OUT_OF_RANGE) is warned
    warning = data_set_out_of_distribution(summary, len(data), "set")
    if warned:
        assert warning is not None and warning.startswith("set: out of distribution: ")
        assert next(iter(summary["by_feature"])) == feature_names(settings)[3]  # the moved feature first
    else:
        assert warning is None and summary["share"] < 0.05
