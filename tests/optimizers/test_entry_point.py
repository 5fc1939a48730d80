"""A third-party calibrator, declared only in the `wrist_env.optimizers` entry-point group, is found and runs."""

import subprocess
import sys

import numpy as np
import pytest

import optimizers
from optimizers import registry


def test_third_party_optimizer_through_the_entry_point(third_party_optimizer):
    name = third_party_optimizer
    assert name not in registry._REGISTRY  # not registered by anyone yet
    assert name in optimizers.available()

    cls = optimizers.get(name)
    assert cls.__module__ == "thirdparty_opt" and cls.__name__ == "ThirdPartyRandom"
    assert issubclass(cls, optimizers.Optimizer) and cls.name == name

    opt = optimizers.make(name, dim=3, budget=10, seed=4, lower=[-1.0, 0.0, 2.0], upper=[0.0, 1.0, 3.0])
    result = optimizers.minimize(opt, lambda x: np.sum(x**2, axis=1))
    assert result.nfev == 10 and len(result.history_x) == 10
    assert np.all(result.history_x >= [-1.0, 0.0, 2.0]) and np.all(result.history_x <= [0.0, 1.0, 3.0])


def test_third_party_optimizer_is_seen_by_a_subprocess(third_party_optimizer):
    """The fixture also puts the package on PYTHONPATH, for tests that run `wrist-bench` as a command."""
    code = "import optimizers; print(' '.join(optimizers.available()))"
    names = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.split()
    assert third_party_optimizer in names and "random" in names


def test_unknown_name_lists_the_third_party_one(third_party_optimizer):
    with pytest.raises(optimizers.UnknownOptimizerError, match=third_party_optimizer):
        optimizers.get("no-such-optimizer")


def test_registry_is_clean_without_the_fixture():
    """The fixture's teardown removes the name (whatever ran before this test)."""
    assert "third-party-random" not in optimizers.available()
