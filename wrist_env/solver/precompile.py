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

The second process runs `wrist_env.solver.parts` (`python -m wrist_env.solver.parts {smooth,trilinear} MODEL`)
on the simulated model, saved for it to a temporary folder (its arrays type the kernels); `parts` holds what it
compiles, this module only decides whether to start it, and starts it.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tempfile
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING

from wrist_env.solver import kernel

if TYPE_CHECKING:
    from wrist_env.model import Model

NORMALS = ("smooth", "trilinear")
"""The two kinds of contact normal, each its own compiled kernels (`SolverSettings.smooth_normals`)."""


def cold(entry) -> bool:
    """Whether the compiled entry point `entry` has nothing in Numba's cache (so it will compile). False
    where Numba's cache cannot be read this way (its private index API changed)."""
    try:
        return not entry._cache._cache_file._load_index()
    except (AttributeError, OSError, ValueError):
        return False


def wanted(settings) -> bool:
    """Whether `compiling` starts a second process for the kernel `Settings` `settings` (`arrays.settings_tuple`):
    its entry point is a preconditioned one, not compiled or loaded in this process yet, with nothing in the
    cache, on a machine with more than one core."""
    return _wanted(kernel.entry(settings))


def _wanted(entry) -> bool:
    preconditioned = entry in (kernel.run_preconditioned, kernel.run_trilinear_preconditioned)
    return preconditioned and not entry.signatures and (os.cpu_count() or 1) >= 2 and cold(entry)


def _start(smooth: bool, model: Model) -> tuple[subprocess.Popen, Path] | None:
    """(the second process, on `model` saved for it into a new temporary folder; that folder), or None where the
    model cannot be saved or the process started (this process then compiles the parts itself, as on one core)."""
    try:
        folder = Path(tempfile.mkdtemp(prefix="wrist_env_parts_"))
    except OSError:
        return None
    try:
        model.save(folder / "model")
        command, home = helper_command(smooth, folder / "model")
        return subprocess.Popen(command, cwd=home, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL), folder
    except OSError:
        shutil.rmtree(folder, ignore_errors=True)
        return None


def helper_command(smooth: bool, model: Path) -> tuple[list[str], Path]:
    """The second process's command (on the model saved at `model`, without its suffixes) and working folder:
    the folder holding this very package, so that `-m` imports it and not another copy found first from the
    working folder (a checkout beside an installed copy): its cache is the one this process reads."""
    normals = NORMALS[0] if smooth else NORMALS[1]
    return [sys.executable, "-m", "wrist_env.solver.parts", normals, str(model)], Path(__file__).resolve().parents[2]


@contextmanager
def compiling(settings, model: Model):
    """Around the first calls of the entry point for the kernel `Settings` `settings` on `model`: yields the
    entry point, with the parts compiling in a second process meanwhile where `wanted` says so; that process
    ends when the block ends (by then its work is done, or done here too), and the model's copy with it."""
    entry = kernel.entry(settings)
    started = _start(bool(settings.smooth_normals), model) if _wanted(entry) else None
    try:
        yield entry
    finally:
        if started is not None:
            helper, folder = started
            helper.terminate()
            helper.wait()
            shutil.rmtree(folder, ignore_errors=True)
