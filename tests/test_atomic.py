"""The one atomic writer: whole files or nothing, unique temporary names, the umask honoured."""

from __future__ import annotations

import subprocess
import sys
import threading
from pathlib import Path

import numpy as np
import pytest

from unstack.atomic import (
    atomic_path,
    atomic_save_array,
    atomic_write,
    atomic_write_text,
    check_output_path,
    folder_writer,
    process_umask,
)
from unstack.errors import InvalidArgument


def test_a_failed_write_leaves_neither_target_nor_temporary(tmp_path: Path) -> None:
    target = tmp_path / "out.json"

    def half_then_fail(stream: object) -> None:
        stream.write(b'{"half":')  # type: ignore[attr-defined]
        raise OSError("disk full")

    from unstack.errors import InvalidArgument

    with pytest.raises(InvalidArgument, match=r"out.json: cannot write there: disk full; nothing was written"):
        atomic_write(target, half_then_fail)  # the error of a full disk has no file name: the output's is said
    assert list(tmp_path.iterdir()) == []


def test_a_failed_write_keeps_the_old_file_whole(tmp_path: Path) -> None:
    target = tmp_path / "out.txt"
    target.write_text("old")
    with pytest.raises(RuntimeError, match="boom"), atomic_path(target) as temporary:
        temporary.write_text("new but unfinished")
        raise RuntimeError("boom")
    assert target.read_text() == "old"
    assert [p.name for p in tmp_path.iterdir()] == ["out.txt"]


def test_concurrent_writers_never_share_a_temporary_name(tmp_path: Path) -> None:
    target = tmp_path / "shared.txt"
    texts = [f"writer {number}\n" * 2000 for number in range(8)]
    threads = [threading.Thread(target=atomic_write_text, args=(target, text)) for text in texts]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    assert target.read_text() in texts
    assert [p.name for p in tmp_path.iterdir()] == ["shared.txt"]


def test_the_written_mode_follows_the_umask(tmp_path: Path) -> None:
    target = tmp_path / "points.npy"
    atomic_save_array(target, np.arange(3.0))
    assert target.stat().st_mode & 0o777 == 0o666 & ~process_umask()
    np.testing.assert_array_equal(np.load(target), np.arange(3.0))


@pytest.mark.parametrize("suffix", [".png", ".svg"])
def test_a_figure_is_written_in_the_format_of_its_suffix(tmp_path: Path, suffix: str) -> None:
    from matplotlib.figure import Figure

    from unstack.atomic import atomic_save_figure

    target = tmp_path / f"plot{suffix}"
    atomic_save_figure(Figure(figsize=(1, 1)), target)
    head = target.read_bytes()[:64]
    assert head.startswith(b"\x89PNG") if suffix == ".png" else b"<?xml" in head


def test_a_missing_folder_is_refused_before_writing(tmp_path: Path) -> None:
    with pytest.raises(InvalidArgument, match=r"the folder .* does not exist"):
        atomic_write_text(tmp_path / "no" / "out.json", "{}")


def test_an_output_with_the_longest_name_the_file_system_allows_is_written(tmp_path: Path) -> None:
    target = tmp_path / ("c" * 250 + ".json")
    atomic_write_text(target, "{}")
    assert target.read_text() == "{}" and [path.name for path in tmp_path.iterdir()] == [target.name]


@pytest.mark.parametrize("kind", ["fifo", "link-to-a-pipe", "loop"])
def test_an_output_that_is_a_pipe_or_a_symlink_loop_is_refused(tmp_path: Path, kind: str) -> None:
    """A link to a pipe is what /dev/stdout is when the output goes into one."""
    import os

    target = tmp_path / "out.json"
    if kind == "fifo":
        os.mkfifo(target)
    elif kind == "link-to-a-pipe":
        pipe = os.pipe()
        target.symlink_to(f"/proc/self/fd/{pipe[1]}")  # the pipe's end through /proc, as /dev/stdout links it
    else:
        target.symlink_to(tmp_path / "other.json")
        (tmp_path / "other.json").symlink_to(target)
    try:
        with pytest.raises(InvalidArgument, match=r"cannot write there: it is a (pipe|symlink loop)"):
            check_output_path(target)
    finally:
        if kind == "link-to-a-pipe":
            os.close(pipe[0])
            os.close(pipe[1])


def test_a_folder_writer_excludes_a_second_writer_and_leaves_no_lock(tmp_path: Path) -> None:
    held = r"another unstack run \(pid \d+\) is writing results in this folder"
    second = folder_writer(tmp_path, "results")
    with folder_writer(tmp_path, "results"), pytest.raises(InvalidArgument, match=held), second:
        pass
    assert list(tmp_path.iterdir()) == []
    with folder_writer(tmp_path, "results"):  # free again once the block ended
        pass


def test_the_lock_of_a_killed_writer_does_not_hold(tmp_path: Path) -> None:
    holder = (
        "import os, sys; from unstack.atomic import folder_writer\n"
        f"with folder_writer({str(tmp_path)!r}, 'results'):\n"
        "    print('held', flush=True); os.kill(os.getpid(), 9)"
    )
    killed = subprocess.run([sys.executable, "-c", holder], capture_output=True, text=True, timeout=60)
    assert killed.stdout == "held\n" and killed.returncode == -9
    assert [path.name for path in tmp_path.iterdir()] == [".unstack-writer.lock"]
    with folder_writer(tmp_path, "results"):
        pass
    assert list(tmp_path.iterdir()) == []


def test_writing_to_a_symlink_writes_through_it_and_keeps_the_link(tmp_path: Path) -> None:
    real = tmp_path / "real.json"
    real.write_text("old")
    link = tmp_path / "link.json"
    link.symlink_to(real.name)
    atomic_write_text(link, "new")
    assert link.is_symlink() and real.read_text() == "new"
