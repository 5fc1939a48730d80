"""The block mass's kernels compiled in a second process while `simulate.warm` compiles the entry point.

A cold compile of the default entry point (`kernel.run_preconditioned`) takes about a minute on one core,
a third of it the block mass's own kernels: the tangent (`tangent.tangent`), the membrane's substeps
(`membrane.substep`) and the mass (`preconditioner.block_mass`), which the entry point reaches only after
the force kernels. When the entry point's cache is empty, `start` runs `parts` in a second process: it
compiles those three for the entry point's argument types (Numba writes each to its cache), and the entry
point, compiling in the first process meanwhile, loads each from the cache when it reaches it instead of
compiling it, if it is there by then (a part still compiling is compiled twice: the answer is the same).
`simulate` calls the entry point through `compiling`, so a process's first simulation does this by itself;
on P1's trial from an empty cache, a warm-up took 38–39 s instead of 57 s on 2 cores (the tangent and the
substeps loaded, the mass compiled in both).

The second process runs `wrist_env.solver.parts` (`python -m wrist_env.solver.parts {smooth,trilinear}`),
which holds what it compiles; this module only decides whether to start it, and starts it.
"""

from __future__ import annotations

import os
import subprocess
import sys
from contextlib import contextmanager
from pathlib import Path

from wrist_env.solver import kernel

NORMALS = ("smooth", "trilinear")
"""The two kinds of contact normal, each its own compiled kernels (`SolverSettings.smooth_normals`)."""


def cold(entry) -> bool:
    """Whether the compiled entry point `entry` has nothing in Numba's cache (so it will compile). False
    where Numba's cache cannot be read this way (its private index API changed)."""
    try:
        return not entry._cache._cache_file._load_index()
    except (AttributeError, OSError, ValueError):
        return False


def start(settings) -> subprocess.Popen | None:
    """A process compiling the parts for the kernel `Settings` `settings` (`arrays.settings_tuple`), if its
    entry point is a preconditioned one, not compiled or loaded in this process yet, with nothing in the
    cache, on a machine with more than one core; else None."""
    return _start(kernel.entry(settings), bool(settings.smooth_normals))


def _start(entry, smooth: bool) -> subprocess.Popen | None:
    preconditioned = entry in (kernel.run_preconditioned, kernel.run_trilinear_preconditioned)
    if not preconditioned or entry.signatures or (os.cpu_count() or 1) < 2 or not cold(entry):
        return None
    command, home = helper_command(smooth)
    return subprocess.Popen(command, cwd=home, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)


def helper_command(smooth: bool) -> tuple[list[str], Path]:
    """The second process's command and working folder: the folder holding this very package, so that
    `-m` imports it and not another copy found first from the working folder (a checkout beside an
    installed copy): its cache is the one this process reads."""
    normals = NORMALS[0] if smooth else NORMALS[1]
    return [sys.executable, "-m", "wrist_env.solver.parts", normals], Path(__file__).resolve().parents[2]


@contextmanager
def compiling(settings):
    """Around the first calls of the entry point for the kernel `Settings` `settings`: yields the entry
    point, with the parts compiling in a second process meanwhile where `start` says so; that process
    ends when the block ends (by then its work is done, or done here too)."""
    entry = kernel.entry(settings)
    helper = _start(entry, bool(settings.smooth_normals))
    try:
        yield entry
    finally:
        if helper is not None:
            helper.terminate()
            helper.wait()
