"""Where an experiment's results go: a folder, a JSON document, and its picture.

Every ``unstack experiment`` command writes through here, so that a results folder is
checked once, every document is written whole or not at all (an interrupted run leaves no
half-written file), and the command prints where its files are.

Examples
--------
>>> import tempfile
>>> from pathlib import Path
>>> folder = results_folder(Path(tempfile.mkdtemp()) / "results")
>>> [path.name for path in save_results(folder, "table1.json", [{"n": 3, "exact": 29}])]
['table1.json']
>>> (folder / "table1.json").read_text().splitlines()[:3]
['[', '  {', '    "n": 3,']
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

from unstack.atomic import check_folder_path, folder_writer
from unstack.jsonio import report_text

__all__ = ["checkpoint_folder", "results_folder", "save_results"]


def results_folder(out: str | os.PathLike[str]) -> Path:
    """The folder ``out``, made if missing; an existing file there is refused.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> afile = Path(tempfile.mkdtemp()) / "afile"
    >>> _ = afile.write_text("")
    >>> results_folder(afile)
    Traceback (most recent call last):
    ...
    unstack.errors.InvalidArgument: ...afile: expected a folder for the results, got a file
    """
    folder = check_folder_path(out)
    folder.mkdir(parents=True, exist_ok=True)
    return folder


@contextlib.contextmanager
def checkpoint_folder(checkpoints: str | os.PathLike[str] | None) -> Iterator[Path | None]:
    """The folder an experiment keeps each pile's result in, made if missing and held while the
    block runs (:func:`unstack.atomic.folder_writer`): a second run on it at the same time is
    refused instead of doing every pile again. ``None`` (no checkpoints) gives ``None``.

    Examples
    --------
    >>> import tempfile
    >>> with checkpoint_folder(Path(tempfile.mkdtemp()) / "piles") as folder:
    ...     folder.name, folder.is_dir()
    ('piles', True)
    """
    if checkpoints is None:
        yield None
        return
    folder = Path(checkpoints)
    folder.mkdir(parents=True, exist_ok=True)
    with folder_writer(folder, "an experiment's piles"):
        yield folder


def save_results(
    folder: Path,
    name: str,
    result: Any,
    plot: Callable[[Any, Path], Any] | None = None,
    picture: str | None = None,
) -> list[Path]:
    """Write ``result`` as the JSON document ``folder/name`` and, given ``plot``, its picture.

    Parameters
    ----------
    folder : Path
        A results folder (:func:`results_folder`).
    name : str
        The document's file name (``container.json``).
    result : JSON-ready value
    plot : callable, optional
        ``plot(result, path)`` draws the picture (the experiment module's ``plot_*``).
    picture : str, optional
        The picture's file name (default: the document's with ``.png``).

    Returns
    -------
    list of Path
        The files written, the document first.
    """
    from unstack.atomic import atomic_write_text

    document = folder / name
    atomic_write_text(document, report_text(result))
    written = [document]
    if plot is not None:
        path = folder / (picture or Path(name).with_suffix(".png").name)
        plot(result, path)
        written.append(path)
    return written


def stored_result(path: Path, key: dict[str, Any]) -> dict[str, Any] | None:
    """The result a checkpoint file holds for ``key``: ``None`` when the file is missing, damaged
    (not JSON, or not ``{"key": ..., "result": {...}}``) or of another run -- the pile is then run again.

    Examples
    --------
    >>> import tempfile
    >>> path = Path(tempfile.mkdtemp()) / "pile.json"
    >>> _ = path.write_text("null")
    >>> stored_result(path, {"seed": 0}) is None
    True
    >>> _ = path.write_text('{"key": {"seed": 0}, "result": {"runs": {}}}')
    >>> stored_result(path, {"seed": 0})
    {'runs': {}}
    """
    try:
        stored = json.loads(path.read_text())
    except (OSError, ValueError):
        return None
    if not isinstance(stored, dict) or stored.get("key") != key or not isinstance(stored.get("result"), dict):
        return None
    result: dict[str, Any] = stored["result"]
    return result


def file_digest(path: Path) -> str:
    """SHA-256 of a file's bytes (a model or a disturbance model a run's results rest on)."""
    return hashlib.sha256(path.read_bytes()).hexdigest()


def model_digest(model: Any) -> str:
    """SHA-256 of a support model: its metadata, its feature settings and its file's bytes (two
    files of one metadata hold other estimators)."""
    digest = hashlib.sha256(json.dumps(model.metadata, sort_keys=True, default=str).encode())
    digest.update(json.dumps(model.features.to_dict(), sort_keys=True).encode())
    source = Path(str(model.source)) if getattr(model, "source", "") else None
    if source is not None and source.is_file():
        digest.update(source.read_bytes())
    return digest.hexdigest()
