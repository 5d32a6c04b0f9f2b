"""One atomic writer for every file the project writes.

A file is written to a uniquely named temporary file in the target's folder, flushed to disk
(``fsync``), given the mode a plain ``open`` would give it under the process's umask, and
renamed over the target. A reader never sees a half-written file, two writers never share a
temporary name, and a failure (an exception, a full disk) leaves neither a partial target nor
a temporary file behind. The umask is read, never changed.

Examples
--------
>>> import tempfile, pathlib
>>> folder = pathlib.Path(tempfile.mkdtemp())
>>> atomic_write_text(folder / "note.txt", "hello\\n")
>>> (folder / "note.txt").read_text()
'hello\\n'
>>> atomic_write_bytes(folder / "blob.bin", b"\\x00\\x01")
>>> (folder / "blob.bin").read_bytes()
b'\\x00\\x01'
>>> sorted(p.name for p in folder.iterdir())
['blob.bin', 'note.txt']
"""

from __future__ import annotations

import contextlib
import os
import tempfile
from collections.abc import Callable, Iterable, Iterator
from pathlib import Path
from typing import Any, BinaryIO

__all__ = [
    "atomic_path",
    "atomic_save_array",
    "atomic_save_figure",
    "atomic_write",
    "atomic_write_bytes",
    "atomic_write_text",
    "check_output_path",
    "folder_writer",
    "process_umask",
]

#: The lock file a run writing a folder holds (:func:`folder_writer`); removed when the run ends.
LOCK_NAME = ".unstack-writer.lock"


def process_umask() -> int:
    """The process's umask, read without changing it.

    Read from ``/proc/self/status``; elsewhere from the mode of a freshly created file.

    Returns
    -------
    int

    Examples
    --------
    >>> 0 <= process_umask() <= 0o777
    True
    """
    try:
        with open("/proc/self/status", encoding="ascii") as status:
            for line in status:
                if line.startswith("Umask:"):
                    return int(line.split()[1], 8)
    except (OSError, ValueError):
        pass
    with tempfile.TemporaryDirectory() as folder:
        probe = Path(folder) / "probe"
        descriptor = os.open(probe, os.O_CREAT | os.O_WRONLY, 0o777)
        os.close(descriptor)
        return 0o777 & ~probe.stat().st_mode


def check_output_path(path: str | os.PathLike[str], *, inputs: Iterable[str | os.PathLike[str] | None] = ()) -> Path:
    """Check, before any work, that a file can be written at ``path``.

    Parameters
    ----------
    path : str or path-like
        Where an output will go.
    inputs : iterable of str or path-like
        Files the same work reads (``None`` and ``"-"``, standard input, are passed over):
        ``path`` must not be one of them, or the output would replace its own input.

    Returns
    -------
    pathlib.Path

    Raises
    ------
    InvalidArgument
        The folder does not exist or is not a folder, ``path`` is a folder, or it is one of
        ``inputs``.

    Examples
    --------
    >>> check_output_path("/no/such/out.json")
    Traceback (most recent call last):
    ...
    unstack.errors.InvalidArgument: /no/such/out.json: cannot write there: the folder /no/such does not exist
    >>> check_output_path("pile.json", inputs=["./pile.json"])
    Traceback (most recent call last):
    ...
    unstack.errors.InvalidArgument: pile.json: cannot write there: it is the input file ./pile.json
    """
    from unstack.errors import InvalidArgument
    from unstack.jsonio import special_file

    if not isinstance(path, str | os.PathLike):
        raise InvalidArgument(f"expected a file name for the output (a str or path-like), got {type(path).__name__}")
    if str(path) == "-":
        raise InvalidArgument("-: expected a file name for the output (--json prints the document on standard output)")
    if str(path) == "":
        raise InvalidArgument("expected a file name for the output, got an empty one")
    if str(path).endswith(("/", os.sep)):
        raise InvalidArgument(f"{path}: expected a file name for the output, got a folder's (it ends with '/')")
    target = Path(path)
    kind = special_file(target)  # through any link: /dev/stdout is a pipe or a terminal
    if kind is not None:  # a rename would replace a pipe or a device with a file
        raise InvalidArgument(f"{path}: cannot write there: it is {kind}, not a regular file")
    if target.is_symlink():  # write through the link: a rename onto it would replace the link itself
        target = Path(os.path.realpath(target))
    for given in inputs:
        if given is not None and str(given) != "-" and _same_file(target, Path(given)):
            raise InvalidArgument(f"{path}: cannot write there: it is the input file {given}")
    folder = target.parent
    if target.is_dir():
        raise InvalidArgument(f"{path}: cannot write there: it is a folder")
    if not folder.exists():
        raise InvalidArgument(f"{path}: cannot write there: the folder {folder} does not exist")
    if not folder.is_dir():
        raise InvalidArgument(f"{path}: cannot write there: {folder} is not a folder")
    if not os.access(folder, os.X_OK):
        raise InvalidArgument(
            f"{path}: cannot write there: the folder {folder} cannot be entered (no execute permission)"
        )
    if not os.access(folder, os.W_OK):
        raise InvalidArgument(f"{path}: cannot write there: the folder {folder} is not writable")
    return target


def check_folder_path(path: str | os.PathLike[str], what: str = "the results") -> Path:
    """Check, before any work, that ``path`` is a folder or can be made one.

    Raises
    ------
    InvalidArgument
        ``path`` or a folder above it is a file.

    Examples
    --------
    >>> check_folder_path("/dev/null/results")
    Traceback (most recent call last):
    ...
    unstack.errors.InvalidArgument: /dev/null/results: expected a folder for the results, but /dev/null is a file
    """
    from unstack.errors import InvalidArgument

    folder = Path(path)
    for place in (folder, *folder.parents):
        if place.exists() or place.is_symlink():
            if not place.is_dir():
                where = "got a file" if place == folder else f"but {place} is a file"
                raise InvalidArgument(f"{path}: expected a folder for {what}, {where}")
            break
    return folder


def _same_file(first: Path, second: Path) -> bool:
    """Whether two paths name one file (one that exists: the same inode; else the same absolute path)."""
    try:
        return os.path.samefile(first, second)
    except OSError:
        return os.path.abspath(first) == os.path.abspath(second)  # no resolve(): a symlink loop raises there


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike[str]) -> Iterator[Path]:
    """Yield a unique temporary path beside ``path``; on success it replaces ``path``.

    The temporary name is short (``.unstack-XXXXXXXX.tmp`` and the target's suffix), so any
    name the file system allows for ``path`` can be written.

    For writers that insist on a file name (``savefig``, ``np.save``): write to the yielded
    path; when the block ends without an exception the file is synced and renamed over
    ``path``; otherwise it is removed. The temporary name keeps the target's suffix, so a
    writer that picks its format from the suffix picks the right one.

    Parameters
    ----------
    path : str or path-like

    Yields
    ------
    pathlib.Path

    Examples
    --------
    >>> import tempfile, pathlib
    >>> target = pathlib.Path(tempfile.mkdtemp()) / "out.txt"
    >>> with atomic_path(target) as temporary:
    ...     _ = temporary.write_text("done")
    >>> target.read_text()
    'done'
    """
    target = check_output_path(path)
    try:
        handle, name = tempfile.mkstemp(prefix=".unstack-", suffix=f".tmp{target.suffix}", dir=target.parent)
    except OSError as error:  # a folder that looks writable but is not (/proc, a full disk)
        from unstack.errors import InvalidArgument

        raise InvalidArgument(f"{path}: cannot write there: {error.strerror or error}") from None
    os.close(handle)
    temporary = Path(name)
    try:
        yield temporary
        with open(temporary, "rb+") as stream:
            os.fsync(stream.fileno())
        os.chmod(temporary, 0o666 & ~process_umask())
        os.replace(temporary, target)
    except OSError as error:  # a disk that fills while writing, say: the output's name, nothing half-written
        if error.filename is not None:
            raise
        from unstack.errors import InvalidArgument

        raise InvalidArgument(f"{path}: cannot write there: {error.strerror or error}; nothing was written") from None
    finally:
        temporary.unlink(missing_ok=True)


def atomic_write(path: str | os.PathLike[str], write: Callable[[BinaryIO], Any]) -> None:
    """Call ``write`` on a binary stream; its bytes replace ``path`` atomically.

    Parameters
    ----------
    path : str or path-like
    write : callable
        Receives the open binary stream.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> target = pathlib.Path(tempfile.mkdtemp()) / "out.bin"
    >>> atomic_write(target, lambda stream: stream.write(b"abc"))
    >>> target.read_bytes()
    b'abc'
    """
    with atomic_path(path) as temporary, open(temporary, "wb") as stream:
        write(stream)


def atomic_write_bytes(path: str | os.PathLike[str], data: bytes) -> None:
    """Write ``data`` to ``path`` atomically (see the module).

    Examples
    --------
    >>> import tempfile, pathlib
    >>> target = pathlib.Path(tempfile.mkdtemp()) / "out.bin"
    >>> atomic_write_bytes(target, b"xyz")
    >>> target.read_bytes()
    b'xyz'
    """
    atomic_write(path, lambda stream: stream.write(data))


def atomic_write_text(path: str | os.PathLike[str], text: str) -> None:
    """Write ``text`` (UTF-8) to ``path`` atomically: a reader never sees a half-written file.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> target = pathlib.Path(tempfile.mkdtemp()) / "out.json"
    >>> atomic_write_text(target, "{}")
    >>> target.read_text()
    '{}'
    """
    atomic_write_bytes(path, text.encode("utf-8"))


def atomic_save_array(path: str | os.PathLike[str], array: Any) -> None:
    """Write a NumPy array as ``.npy`` atomically, never with pickled objects.

    Examples
    --------
    >>> import tempfile, pathlib, numpy as np
    >>> target = pathlib.Path(tempfile.mkdtemp()) / "points.npy"
    >>> atomic_save_array(target, np.zeros((2, 3)))
    >>> np.load(target).shape
    (2, 3)
    """
    import numpy as np

    atomic_write(path, lambda stream: np.save(stream, np.asarray(array), allow_pickle=False))


def atomic_save_figure(figure: Any, path: str | os.PathLike[str], *, dpi: int = 110, **savefig: Any) -> None:
    """Save a matplotlib figure atomically; the format follows the suffix (``.png``, ``.svg``, ``.pdf``).

    Parameters
    ----------
    figure : matplotlib.figure.Figure
    path : str or path-like
    dpi : int
    **savefig
        Passed on to ``Figure.savefig`` (``bbox_inches``, ...).

    Examples
    --------
    >>> import tempfile, pathlib
    >>> from matplotlib.figure import Figure
    >>> target = pathlib.Path(tempfile.mkdtemp()) / "plot.svg"
    >>> atomic_save_figure(Figure(), target)
    >>> target.read_text().lstrip().startswith("<?xml")
    True
    """
    suffix = Path(path).suffix.lstrip(".").lower() or "png"
    dateless = {"svg": {"Date": None}, "pdf": {"CreationDate": None}}.get(suffix)  # no time of writing in the file
    if dateless is not None and "metadata" not in savefig:
        savefig["metadata"] = dateless
    with atomic_path(path) as temporary:
        figure.savefig(temporary, dpi=dpi, format=suffix, **savefig)


@contextlib.contextmanager
def folder_writer(folder: str | os.PathLike[str], what: str, error: type[Exception] | None = None) -> Iterator[Path]:
    """Hold ``folder``'s writer lock while the block runs: a second unstack run writing the
    same folder at the same time is refused instead of redoing the work and mixing its files.

    The lock is an advisory ``flock`` on :data:`LOCK_NAME` in the folder (made if missing),
    released by the system when the process ends however it ends, so a killed run leaves no lock
    that holds; the file is removed when the block ends. Where the system has no ``flock``
    (Windows), nothing is locked.

    Parameters
    ----------
    folder : path-like
        The folder the run writes.
    what : str
        What the run writes there, for the message ("a data set").
    error : exception type, optional
        Raised when another run holds the lock (default :class:`~unstack.errors.InvalidArgument`).

    Examples
    --------
    >>> import tempfile
    >>> folder = Path(tempfile.mkdtemp())
    >>> with folder_writer(folder, "a data set"):
    ...     with folder_writer(folder, "a data set"):
    ...         pass
    Traceback (most recent call last):
    ...
    unstack.errors.InvalidArgument: ...: another unstack run (pid ...) is writing a data set in this folder; ...
    >>> list(folder.iterdir())
    []
    """
    from unstack.errors import InvalidArgument

    try:
        import fcntl
    except ImportError:  # pragma: no cover - no POSIX locks on this system
        yield Path(folder)
        return
    target = Path(folder)
    path = target / LOCK_NAME
    while True:
        try:
            handle = os.open(path, os.O_RDWR | os.O_CREAT, 0o644)
        except OSError as failure:
            raise InvalidArgument(f"{target}: cannot write there: {failure.strerror}") from None
        try:
            fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            holder = os.read(handle, 32).decode("ascii", "replace").strip()
            os.close(handle)
            pid = f" (pid {holder})" if holder.isdigit() else ""
            raise (error or InvalidArgument)(
                f"{target}: another unstack run{pid} is writing {what} in this folder; wait for it to end"
            ) from None
        with contextlib.suppress(OSError):
            if os.stat(path).st_ino == os.fstat(handle).st_ino:
                break  # the file locked is still the one named: the lock holds
        os.close(handle)  # the holder before us removed it meanwhile: lock the new one
    try:
        os.ftruncate(handle, 0)
        os.write(handle, str(os.getpid()).encode("ascii"))
        yield target
    finally:
        with contextlib.suppress(OSError):
            path.unlink()
        os.close(handle)
