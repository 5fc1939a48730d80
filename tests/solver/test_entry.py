"""The kernel's compiled entry points (`kernel.entry`): each solver compiles only its own, and local worker
processes start after their parent compiled it (`simulate.warm`)."""

import os
import subprocess
import sys
from dataclasses import replace
from pathlib import Path

import pytest

from wrist_env.solver import kernel
from wrist_env.solver.arrays import EXPERIMENTAL, settings_tuple
from wrist_env.solver.settings import SolverSettings


@pytest.mark.parametrize(
    "settings, expected",
    [
        (SolverSettings().diagonal(), kernel.run),
        (SolverSettings(), kernel.run_preconditioned),
        (replace(SolverSettings().diagonal(), block_mass=True), kernel.run_preconditioned),
        (replace(SolverSettings().diagonal(), membrane_substeps=3), kernel.run_preconditioned),
        (replace(SolverSettings().diagonal(), predict=True), kernel.run_preconditioned),
        (replace(SolverSettings().diagonal(), smooth_normals=False), kernel.run_trilinear),
        (replace(SolverSettings(), smooth_normals=False), kernel.run_trilinear_preconditioned),
    ],
)
def test_each_setting_picks_the_entry_point_that_can_run_it(settings, expected):
    assert kernel.entry(settings_tuple(settings, EXPERIMENTAL)) is expected


def test_a_default_simulation_compiles_one_entry_point_and_workers_compile_none(tmp_path):
    """In a fresh process, starting local workers warms the default solver's entry point in the parent
    (`kernel.run_preconditioned`, and no other entry point), and a worker's first simulation loads it from Numba's cache
    instead of compiling it."""
    (tmp_path / "probe.py").write_text(
        "def first_simulation():\n"
        "    from wrist_env.participants.registry import warm_solver\n"
        "    from wrist_env.solver import kernel\n"
        "    warm_solver()\n"
        "    entry = kernel.run_preconditioned\n"
        "    return sum(entry.stats.cache_hits.values()), sum(entry.stats.cache_misses.values())\n"
    )
    (tmp_path / "main.py").write_text(
        "from probe import first_simulation\n"
        "from wrist_env.participants.registry import warm_solver\n"
        "from wrist_env.runs.executor import executor\n"
        "from wrist_env.solver import kernel\n"
        "if __name__ == '__main__':\n"
        "    with executor(workers=2, warm=warm_solver) as ex:\n"
        "        entries = (kernel.run, kernel.run_preconditioned, kernel.run_trilinear, kernel.run_trilinear_preconditioned)\n"
        "        print(' '.join(f.__name__ for f in entries if f.signatures))\n"
        "        print(*ex.submit(first_simulation).result())\n"
    )
    done = subprocess.run([sys.executable, "main.py"], cwd=tmp_path, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr[-3000:]
    compiled, loaded = done.stdout.splitlines()[:2]
    assert compiled == "run_preconditioned"
    assert loaded == "1 0"  # the worker: one cache hit, no compilation


@pytest.mark.slow
def test_the_parts_a_second_process_compiles_are_the_ones_the_entry_point_calls(tmp_path):
    """`parts.part_signatures` types the block mass's kernels as `kernel.run_preconditioned` calls
    them: compiled first (as the second process does), the entry point's own compile reuses each of them
    and adds no second signature (a mismatch would compile it again, and the second process would save
    nothing). An empty Numba cache, one process (~1 min); under pytest-xdist from an empty cache (CI) the
    conftest's warming of the default solver was this very compile, and its counts are read instead."""
    import json

    recorded = Path(os.environ.get("WRIST_ENV_PARTS_PROBE", "/nonexistent"))
    if recorded.is_file():
        found = json.loads(recorded.read_text())
        if found["cold"]:
            assert found["signatures"] == [["tangent", 1], ["substep", 1], ["block_mass", 1]], found
            return
    probe = (
        "from wrist_env.solver import parts, precompile, simulate\n"
        "from wrist_env.solver.settings import SolverSettings\n"
        "from wrist_env.participants.registry import load_model\n"
        "precompile._wanted = lambda entry: False\n"
        "model = load_model('P1')\n"
        "parts.compile_parts(model, SolverSettings())\n"
        "simulate.warm(model)\n"
        "for dispatcher, _ in parts.part_signatures(model, SolverSettings()):\n"
        "    print(dispatcher.py_func.__name__, len(dispatcher.signatures))\n"
    )
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "numba"))
    done = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, env=env)
    assert done.returncode == 0, done.stderr[-3000:]
    assert done.stdout.split() == ["tangent", "1", "substep", "1", "block_mass", "1"]


def test_a_second_process_compiles_only_from_an_empty_cache():
    """`precompile.wanted` is False for the diagonal mass's entry point (it has no block mass) and for one this
    process has compiled or loaded already."""
    from wrist_env.participants.registry import warm_solver
    from wrist_env.solver import precompile

    assert not precompile.wanted(settings_tuple(SolverSettings().diagonal(), EXPERIMENTAL))
    warm_solver()
    assert kernel.run_preconditioned.signatures
    assert not precompile.wanted(settings_tuple(SolverSettings(), EXPERIMENTAL))


def test_the_second_process_imports_this_package_not_one_in_the_working_folder(tmp_path, monkeypatch):
    """From a folder holding another wrist_env (a checkout beside an installed copy), `python -m` would import
    that one and fill its cache, not the one this process reads: the second process runs from the folder
    holding the package imported here."""
    import wrist_env
    from wrist_env.solver import precompile

    (tmp_path / "wrist_env").mkdir()
    monkeypatch.chdir(tmp_path)
    command, home = precompile.helper_command(True, tmp_path / "model")
    probe = "import wrist_env.solver.parts as p; print(p.__file__)"
    done = subprocess.run([command[0], "-c", probe], cwd=home, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr[-2000:]
    assert Path(done.stdout.strip()).resolve().parents[2] == Path(wrist_env.__file__).resolve().parents[1]
    assert command[1:] == ["-m", "wrist_env.solver.parts", "smooth", str(tmp_path / "model")]


def test_the_second_process_gets_the_simulated_model_and_its_copy_is_removed(built, monkeypatch):
    """From an empty cache, `compiling` saves the simulated model for the second process (whose command names
    it), and removes the copy when the block ends; a model that cannot be saved starts no process, and the
    entry point compiles here alone."""
    from wrist_env.model import Model
    from wrist_env.solver import precompile

    model = built("P1")
    settings = settings_tuple(SolverSettings(), EXPERIMENTAL)
    started = []

    class Process:
        def __init__(self, command, **_):
            started.append(command)
            self.saved = Model.load(command[-1])  # the file is there while the process runs

        def terminate(self):
            pass

        def wait(self):
            return 0

    monkeypatch.setattr(precompile, "_wanted", lambda entry: True)
    monkeypatch.setattr(precompile.subprocess, "Popen", Process)
    with precompile.compiling(settings, model) as entry:
        assert entry is kernel.run_preconditioned
    (command,) = started
    assert command[-2] == "smooth" and command[-3] == "wrist_env.solver.parts"
    assert not Path(command[-1]).parent.exists()

    class Unsaveable:
        def save(self, path):
            raise OSError(28, "No space left on device")

    with precompile.compiling(settings, Unsaveable()) as entry:
        assert entry is kernel.run_preconditioned
    assert len(started) == 1
