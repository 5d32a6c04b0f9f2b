"""unstack leaves a host process's state alone: umask, file descriptors, matplotlib backend."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from unstack.atomic import atomic_write_text, process_umask


def test_the_umask_is_read_without_being_set(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    current = os.umask(0o027)
    os.umask(current)

    def refuse(_mask: int) -> int:
        raise AssertionError("os.umask was called")

    monkeypatch.setattr(os, "umask", refuse)
    assert process_umask() == current
    target = tmp_path / "out.json"
    atomic_write_text(target, "{}")
    assert target.stat().st_mode & 0o777 == 0o666 & ~current


def test_the_umask_fallback_reads_a_new_files_mode(monkeypatch: pytest.MonkeyPatch) -> None:
    import builtins

    current = os.umask(0o022)
    os.umask(current)
    real_open = builtins.open

    def no_proc(file: object, *args: object, **kwargs: object) -> object:
        if str(file) == "/proc/self/status":
            raise OSError("no /proc here")
        return real_open(file, *args, **kwargs)  # type: ignore[call-overload]

    monkeypatch.setattr(builtins, "open", no_proc)
    assert process_umask() == current


def test_plots_keep_the_hosts_backend_and_skip_pyplot(tmp_path: Path) -> None:
    code = f"""
import sys, matplotlib
matplotlib.use("svg")
from unstack.plotting import pyplot, save_figure
plt = pyplot()
figure, axes = plt.subplots(1, 2, figsize=(3, 2))
axes[0].plot([0, 1], [1, 0])
save_figure(figure, {str(tmp_path / "plot.png")!r})
print(matplotlib.get_backend(), "matplotlib.pyplot" in sys.modules)
"""
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert result.stdout.split() == ["svg", "False"]
    assert (tmp_path / "plot.png").read_bytes()[:4] == b"\x89PNG"


def test_a_simulated_world_does_not_touch_file_descriptors(monkeypatch: pytest.MonkeyPatch) -> None:
    pytest.importorskip("pybullet")
    from unstack.sim.settings import SimulationSettings
    from unstack.sim.world import PhysicsWorld, import_pybullet

    import_pybullet()  # the one confined, silenced import (a no-op if already imported)

    calls: list[tuple[object, ...]] = []
    real_dup2 = os.dup2

    def record(*arguments: object) -> None:
        calls.append(arguments)

    monkeypatch.setattr(os, "dup2", record)
    try:
        with PhysicsWorld(SimulationSettings(boxes=(1, 1))) as world:
            world.add_box([0.4, 0.3, 0.3], [1.0, 0.0, 0.5], [0, 0, 0, 1], mass=5.0)
    finally:
        monkeypatch.setattr(os, "dup2", real_dup2)
    assert calls == []


def test_a_world_prints_nothing_on_stdout(repo: Path) -> None:
    pytest.importorskip("pybullet")
    code = (
        "from unstack.sim.world import PhysicsWorld\n"
        "from unstack.sim.settings import SimulationSettings\n"
        "for _ in range(2):\n"
        "    PhysicsWorld(SimulationSettings(boxes=(1, 1))).close()\n"
        "print('{}')\n"
    )
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True, cwd=repo)
    assert result.stdout == "{}\n"


#: What the dependencies unstack imports lazily change in a process on import, and nothing of
#: unstack's own: scikit-learn sets two OpenMP environment variables (when unset), scipy and
#: scikit-learn add warning filters. The reference page names them.
DEPENDENCIES_ENVIRONMENT = {"KMP_DUPLICATE_LIB_OK", "KMP_INIT_AT_FORK"}


@pytest.mark.slow  # a fresh interpreter that imports scikit-learn
def test_a_decision_changes_no_process_state_but_what_its_dependencies_set_on_import(repo: Path) -> None:
    code = (
        "import json, logging, os, random, signal, sys, warnings\n"
        "import numpy as np\n"
        "def state():\n"
        "    return {'environment': dict(os.environ), 'filters': [repr(f) for f in warnings.filters],\n"
        "            'print': repr(np.get_printoptions()), 'random': repr(np.random.get_state()[1][:4]),\n"
        "            'errors': repr(np.geterr()), 'cwd': os.getcwd(), 'root': repr(logging.getLogger().handlers),\n"
        "            'level': logging.getLogger().level, 'sigint': repr(signal.getsignal(signal.SIGINT)),\n"
        "            'recursion': sys.getrecursionlimit(), 'python_random': repr(random.getstate())}\n"
        "before = state()\n"
        "import sklearn, sklearn.tree, scipy.stats  # what unstack imports lazily, imported alone\n"
        "dependencies = state()\n"
        "import unstack\n"
        "scene = unstack.load('examples/pile5.scene.json')\n"
        "unstack.decide(scene); unstack.plan(unstack.load('examples/stack5.supports.json'))\n"
        "after = state()\n"
        "print(json.dumps({'before': before, 'dependencies': dependencies, 'after': after}))\n"
    )
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True, cwd=repo)
    import json

    states = json.loads(result.stdout)
    before, dependencies, after = states["before"], states["dependencies"], states["after"]
    changed = {key for key in set(before["environment"]) | set(after["environment"])
               if before["environment"].get(key) != after["environment"].get(key)}  # fmt: skip
    assert changed <= DEPENDENCIES_ENVIRONMENT
    assert after["environment"] == dependencies["environment"]  # the dependencies' own, nothing of unstack's
    assert after["filters"] == dependencies["filters"]
    for key in ("print", "random", "errors", "cwd", "root", "level", "sigint", "recursion"):
        assert after[key] == before[key], key
    # scikit-learn's tree module draws from Python's random at import: that draw, and none of unstack's
    assert after["python_random"] == dependencies["python_random"]
