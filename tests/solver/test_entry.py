"""The kernel's compiled entry points (`kernel.entry`): each solver compiles only its own, and local worker
processes start after their parent compiled it (`simulate.warm`)."""

import subprocess
import sys
from dataclasses import replace

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
        "    from wrist_env.solver import kernel, simulate\n"
        "    simulate.warm()\n"
        "    entry = kernel.run_preconditioned\n"
        "    return sum(entry.stats.cache_hits.values()), sum(entry.stats.cache_misses.values())\n"
    )
    (tmp_path / "main.py").write_text(
        "from probe import first_simulation\n"
        "from wrist_env.runs.executor import executor\n"
        "from wrist_env.solver import kernel\n"
        "if __name__ == '__main__':\n"
        "    with executor(workers=2) as ex:\n"
        "        entries = (kernel.run, kernel.run_preconditioned, kernel.run_trilinear, kernel.run_trilinear_preconditioned)\n"
        "        print(' '.join(f.__name__ for f in entries if f.signatures))\n"
        "        print(*ex.submit(first_simulation).result())\n"
    )
    done = subprocess.run([sys.executable, "main.py"], cwd=tmp_path, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr[-3000:]
    compiled, loaded = done.stdout.splitlines()[:2]
    assert compiled == "run_preconditioned"
    assert loaded == "1 0"  # the worker: one cache hit, no compilation
