"""Shared fixtures: a hermetic model cache and the built-in participants, built once per session; killing a
parent process to see its workers die with it. Under pytest-xdist, the solver's two entry points are
compiled once, before the workers start (`pytest_configure`)."""

import os
import signal
import subprocess
import sys
import tempfile

import pytest

WARM = (
    "from wrist_env.participants.registry import warm_solver\n"
    "from wrist_env.solver.settings import solver_settings\n"
    "warm_solver(solver_settings({!r}))\n"
)
PARTS_PROBE = (
    "import json, sys\n"
    "from wrist_env.participants.registry import load_model\n"
    "from wrist_env.solver import parts, precompile, simulate\n"
    "from wrist_env.solver.settings import SolverSettings\n"
    "precompile._wanted = lambda entry: False\n"
    "model = load_model('P1')\n"
    "parts.compile_parts(model, SolverSettings())\n"
    "simulate.warm(model)\n"
    "found = [d for d, _ in parts.part_signatures(model, SolverSettings())]\n"
    "cold = not any(d.stats.cache_hits for d in found)\n"
    "counts = [[d.py_func.__name__, len(d.signatures)] for d in found]\n"
    "json.dump({'cold': cold, 'signatures': counts}, open(sys.argv[1], 'w'))\n"
)
"""The default solver's warming, as tests/solver/test_entry.py's parts check wants it: the second process's
parts compiled first, then the entry point, the signature counts written to a file (`PARTS_PROBE_ENV`).
From an empty cache (CI's) that is the check's own cold compile, which the test then reads instead of
compiling everything again in a process of its own (a minute of CI)."""
PARTS_PROBE_ENV = "WRIST_ENV_PARTS_PROBE"


def pytest_configure(config):
    """With workers (`-n`), compile the default and the diagonal solvers' entry points here, one process
    each, at once, before the workers start: each worker then loads them from Numba's cache instead of
    every worker compiling both at the same time (on 2 cores a cold suite spent ~3 minutes more than a
    warm one). Without workers, or in a worker, nothing: the kernels compile on first use."""
    if hasattr(config, "workerinput") or not getattr(config.option, "numprocesses", None):
        return
    from wrist_env.solver.settings import SOLVERS

    probe = os.path.join(tempfile.mkdtemp(prefix="wrist_env_parts_"), "parts.json")
    os.environ[PARTS_PROBE_ENV] = probe  # the workers, started after this, read it
    with tempfile.TemporaryDirectory() as cache:
        env = dict(os.environ, WRIST_ENV_CACHE=cache)
        argv = {s: ["-c", PARTS_PROBE, probe] if s == "default" else ["-c", WARM.format(s)] for s in SOLVERS}
        warming = [subprocess.Popen([sys.executable, *argv[s]], env=env) for s in SOLVERS]
        failed = [s for s, p in zip(SOLVERS, warming) if p.wait() != 0]
    if failed:
        raise pytest.UsageError(f"compiling the solver's entry points failed for {failed} (see above)")


@pytest.fixture(scope="session", autouse=True)
def model_cache(tmp_path_factory):
    """Every test session builds into its own cache (so the build itself is tested), one for all its
    pytest-xdist workers (beside their own temporary folders): a model two workers need is built once, under
    the registry's build lock, and loaded by the other."""
    if os.environ.get("PYTEST_XDIST_WORKER"):
        path = tmp_path_factory.getbasetemp().parent / "wrist_env_cache"
        path.mkdir(exist_ok=True)
    else:
        path = tmp_path_factory.mktemp("wrist_env_cache")
    old = os.environ.get("WRIST_ENV_CACHE")
    os.environ["WRIST_ENV_CACHE"] = str(path)
    yield path
    if old is None:
        os.environ.pop("WRIST_ENV_CACHE", None)
    else:
        os.environ["WRIST_ENV_CACHE"] = old


@pytest.fixture(scope="session")
def built(model_cache):
    """Models of P1–P3 (built on first use, then read from the session cache)."""
    from wrist_env.participants.registry import load_model

    cache = {}

    def get(name):
        if name not in cache:
            cache[name] = load_model(name)
        return cache[name]

    return get


@pytest.fixture(autouse=True)
def participant_registry():
    """Folders a test registers are forgotten after it (those of wider-scoped fixtures, set up
    before it, are kept): a name is one folder within a process (`registry.add_folder` refuses a
    second), and tests reuse names such as U1."""
    from wrist_env.participants import registry

    folders, sources = dict(registry._FOLDERS), dict(registry._SOURCES)
    yield
    registry._FOLDERS.clear()
    registry._FOLDERS.update(folders)
    registry._SOURCES.clear()
    registry._SOURCES.update(sources)


@pytest.fixture
def kill_parent():
    """`kill_parent(proc, workers)`: SIGKILL the process `proc` (a Popen) and assert that its `workers` (psutil
    processes) end with it, within 20 s."""

    def kill(proc, workers) -> None:
        import psutil

        os.kill(proc.pid, signal.SIGKILL)
        proc.wait(timeout=30)
        _, alive = psutil.wait_procs(workers, timeout=20)
        assert not alive, f"workers outlived their parent: {[w.pid for w in alive]}"

    return kill
