"""The disturbance regressor: scikit-learn's contract, counts, files that run no code."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from sklearn.base import clone

from unstack.learning.disturbance import (
    DisturbanceModel,
    DisturbanceRegressor,
    calibration,
    held_out_predictions,
    load_disturbance_model,
    save_disturbance_model,
)
from unstack.learning.model_file import InvalidModel
from unstack.learning.pick_features import PICK_FEATURES


@pytest.fixture
def counts(fixed_rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    features = fixed_rng.uniform(size=(600, len(PICK_FEATURES)))
    moved = fixed_rng.poisson(4.0 * features[:, 3] ** 2)
    return features, moved.astype(float)


def test_init_only_stores_keyword_parameters() -> None:
    regressor = DisturbanceRegressor(max_iter=7, random_state=3)
    assert regressor.get_params()["max_iter"] == 7 and not hasattr(regressor, "estimator_")
    with pytest.raises(TypeError):
        DisturbanceRegressor(7)  # type: ignore[misc]


def test_fit_returns_self_and_sets_fitted_attributes(counts: tuple[np.ndarray, np.ndarray]) -> None:
    features, moved = counts
    regressor = DisturbanceRegressor(max_iter=30, random_state=0)
    assert regressor.fit(features, moved) is regressor
    assert regressor.n_features_in_ == len(PICK_FEATURES) and hasattr(regressor, "estimator_")


def test_predictions_are_non_negative_and_follow_the_signal(counts: tuple[np.ndarray, np.ndarray]) -> None:
    features, moved = counts
    regressor = DisturbanceRegressor(max_iter=60, random_state=0).fit(features, moved)
    low, high = features[:2].copy(), features[:2].copy()
    low[:, 3], high[:, 3] = 0.05, 0.95
    assert (regressor.predict(low) >= 0).all() and (regressor.predict(high) > regressor.predict(low) + 1).all()


def test_the_same_seed_gives_the_same_model(counts: tuple[np.ndarray, np.ndarray]) -> None:
    features, moved = counts
    first = DisturbanceRegressor(max_iter=20, random_state=4).fit(features, moved).predict(features)
    second = clone(DisturbanceRegressor(max_iter=20, random_state=4)).fit(features, moved).predict(features)
    np.testing.assert_array_equal(first, second)


def test_negative_counts_are_refused(counts: tuple[np.ndarray, np.ndarray]) -> None:
    features, moved = counts
    with pytest.raises(ValueError, match="counts of boxes moved"):
        DisturbanceRegressor().fit(features, -moved - 1)


def test_held_out_predictions_keep_each_pile_out_of_its_own_fit(counts: tuple[np.ndarray, np.ndarray]) -> None:
    features, moved = counts
    groups = np.arange(len(moved)) // 60
    predicted = held_out_predictions(DisturbanceRegressor(max_iter=30, random_state=0), features, moved, groups)
    report = calibration(predicted, moved)
    assert report["spearman"] > 0.5 and sum(row["picks"] for row in report["bins"]) == len(moved)


def test_a_model_file_round_trips(counts: tuple[np.ndarray, np.ndarray], tmp_path: Path) -> None:
    features, moved = counts
    fitted = DisturbanceRegressor(max_iter=20, random_state=0).fit(features, moved)
    path = tmp_path / "disturbance.skops"
    save_disturbance_model(DisturbanceModel(fitted.estimator_, PICK_FEATURES, {"note": "test"}), path)
    loaded = load_disturbance_model(path)
    np.testing.assert_allclose(loaded.expected_moves(features[:5]), np.maximum(fitted.predict(features[:5]), 0))
    assert loaded.metadata["note"] == "test"


def test_a_model_of_other_features_is_refused(counts: tuple[np.ndarray, np.ndarray], tmp_path: Path) -> None:
    features, moved = counts
    fitted = DisturbanceRegressor(max_iter=5, random_state=0).fit(features[:, :4], moved)
    path = tmp_path / "other.skops"
    save_disturbance_model(DisturbanceModel(fitted.estimator_, PICK_FEATURES[:4], {}), path)
    with pytest.raises(InvalidModel, match=r"other\.skops.*pick features of this version"):
        load_disturbance_model(path)


def test_a_support_model_file_is_not_a_disturbance_model() -> None:
    from unstack.learning.model_file import default_model_path

    with pytest.raises(InvalidModel, match=r"unsupported model format 'unstack\.model/1'"):
        load_disturbance_model(default_model_path())


def test_rows_of_the_wrong_width_are_refused_in_one_line() -> None:
    with pytest.raises(InvalidModel, match=f"expected rows of {len(PICK_FEATURES)} pick features"):
        load_disturbance_model().expected_moves(np.zeros((2, 3)))


def test_held_out_figures_of_states_from_one_pile_are_refused() -> None:
    from unstack.errors import InvalidArgument
    from unstack.learning.disturbance import DisturbanceRegressor, held_out_predictions

    features = np.random.default_rng(0).normal(size=(12, 3))
    with pytest.raises(InvalidArgument, match=r"at least 2 piles, held out one at a time; these come from 1"):
        held_out_predictions(DisturbanceRegressor(), features, np.zeros(12), np.zeros(12, dtype=int))
