"""Data-set folders: the finished scene files, and a manifest that lists more than are finished."""

from __future__ import annotations

import json
import warnings
from pathlib import Path

import pytest

from unstack.dataset_folders import MANIFEST, config_name, require_configurations
from unstack.errors import UnstackError


def data_set(folder: Path, finished: int, listed: int | None) -> Path:
    """A folder with ``finished`` scene files and, unless ``listed`` is None, a manifest listing that many."""
    for index in range(finished):
        (folder / f"{config_name(index)}.json").write_text("{}")
    if listed is not None:
        manifest = {"format": "unstack.dataset/1", "seed": 0, "configs": listed, "settings": {}}
        (folder / MANIFEST).write_text(json.dumps(manifest))
    return folder


def test_an_unfinished_data_set_is_read_with_a_warning_naming_both_counts(tmp_path: Path) -> None:
    folder = data_set(tmp_path, finished=2, listed=30)
    with pytest.warns(UserWarning, match=r"2 of the 30 configurations its manifest lists are finished"):
        files = require_configurations(folder)
    assert [path.name for path in files] == ["config-0000.json", "config-0001.json"]


@pytest.mark.parametrize(("finished", "listed"), [(3, 3), (3, None), (3, 2)])
def test_a_finished_data_set_or_one_without_a_manifest_is_read_silently(
    tmp_path: Path, finished: int, listed: int | None
) -> None:
    folder = data_set(tmp_path, finished, listed)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert len(require_configurations(folder)) == finished


@pytest.mark.parametrize(
    ("manifest", "message"),
    [
        ("not json", r"manifest\.json: \$: invalid JSON"),
        ('{"format": "unstack.dataset/1", "seed": 0, "configs": "30", "settings": {}}', r"\$\.configs"),
        ("[30]", r"manifest\.json: \$: expected a JSON object"),
    ],
)
def test_a_manifest_that_is_not_a_data_sets_is_refused(tmp_path: Path, manifest: str, message: str) -> None:
    folder = data_set(tmp_path, finished=1, listed=None)
    (folder / MANIFEST).write_text(manifest)
    with pytest.raises(UnstackError, match=message):
        require_configurations(folder)


def test_more_piles_than_a_data_set_holds_are_all_of_them_with_a_warning(tmp_path: Path) -> None:
    from unstack.dataset_folders import first_configurations

    data_set(tmp_path, 2, None)
    assert [path.name for path in first_configurations(tmp_path, 1)] == ["config-0000.json"]
    with pytest.warns(UserWarning, match=r"3 configurations asked for, the data set has 2: all 2 are used"):
        assert len(first_configurations(tmp_path, 3, "configurations")) == 2
