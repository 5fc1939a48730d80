"""Cheap, honest imports: the light modules pull in neither Gymnasium nor the model builder, and the
built-in Gymnasium ids are registered whichever of `wrist_env` and `gymnasium` is imported first."""

import subprocess
import sys

import pytest

HEAVY = ("gymnasium", "wrist_env.builder.pipeline", "trimesh", "igl", "numba", "scipy.optimize", "scipy.spatial")


def _run(code: str) -> str:
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    return done.stdout.strip()


@pytest.mark.parametrize("module", ["wrist_env.design", "wrist_env.frames", "wrist_env.cost", "optimizers"])
def test_light_modules_import_nothing_heavy(module):
    loaded = _run(f"import sys, {module}; print(' '.join(m for m in {HEAVY!r} if m in sys.modules))")
    assert loaded == "", f"importing {module} imported {loaded}"


@pytest.mark.parametrize("order", ["import wrist_env, gymnasium", "import gymnasium, wrist_env"])
def test_builtin_ids_are_registered_in_either_import_order(order):
    ids = _run(f"{order}; print(' '.join(sorted(i for i in gymnasium.registry if i.startswith('wrist_env/'))))")
    assert ids.split() == sorted(
        f"wrist_env/{m}-{p}-v0" for m in ("Calibrate", "Validate", "Idealized") for p in ("P1", "P2", "P3")
    )
