"""Nevergrad's optimizers as calibrators: registration, seeding, batches, threads, and a real calibration cell.

(The contract every calibrator keeps is in test_contract.py, which covers these too.)
"""

import importlib.util
import time

import numpy as np
import pytest

import optimizers
from optimizers import nevergrad_optimizers, registry

pytest.importorskip("nevergrad")


def sphere(x):
    return np.sum((np.atleast_2d(x) - 0.3) ** 2, axis=1)


def test_the_four_methods_are_registered():
    assert set(nevergrad_optimizers.METHODS) <= set(optimizers.available())
    assert optimizers.make("ng-pso", dim=3, budget=5).ng.name == "PSO"


def test_without_nevergrad_the_names_say_which_extra_to_install(monkeypatch):
    monkeypatch.setattr(registry, "_REGISTRY", {k: v for k, v in registry._REGISTRY.items() if not k.startswith("ng-")})
    monkeypatch.setattr(registry, "_UNAVAILABLE", dict(registry._UNAVAILABLE))
    monkeypatch.setattr(importlib.util, "find_spec", lambda name, *a: None)
    nevergrad_optimizers._register_all()
    assert "ng-tbpsa" not in optimizers.available()
    with pytest.raises(registry.UnknownOptimizerError, match=r"TBPSA needs the nevergrad extra.*\[nevergrad\]"):
        optimizers.get("ng-tbpsa")


def test_batch_size_is_the_number_of_workers():
    opt = optimizers.make("ng-twopointsde", dim=4, budget=10, seed=1, batch_size=4)
    assert opt.ng.num_workers == 4
    x = opt.ask()
    assert x.shape == (4, 4)
    opt.tell(x, sphere(x))
    assert opt.ask().shape == (4, 4)
    with pytest.raises(ValueError, match="batch_size"):
        optimizers.make("ng-pso", dim=4, budget=10, batch_size=0)


def test_ngopt_is_seeded_where_its_choice_is_random():
    """NGOpt runs COBYLA (deterministic) one point at a time; with batches it picks a seeded, random method."""

    def history(seed):
        opt = optimizers.make("ng-ngopt", dim=5, budget=24, seed=seed, batch_size=4)
        try:
            return optimizers.minimize(opt, sphere).history_x
        finally:
            opt.close()

    np.testing.assert_array_equal(history(3), history(3))
    assert not np.array_equal(history(3), history(4))


def test_infinite_values_are_told_and_the_run_goes_on():
    opt = optimizers.make("ng-tbpsa", dim=3, budget=30, seed=0, batch_size=5)
    result = optimizers.minimize(opt, lambda x: np.where(np.arange(len(x)) % 2 == 0, np.inf, sphere(x)))
    assert result.nfev == 30 and np.isfinite(result.fun)


def test_close_stops_cobylas_thread():
    opt = optimizers.make("ng-ngopt", dim=5, budget=40, seed=0)
    x = opt.ask()
    opt.tell(x, sphere(x))
    opt.ask()
    thread = opt.ng.optim._messaging_thread
    assert thread.is_alive()
    opt.close()
    for _ in range(50):
        if not thread.is_alive():
            break
        time.sleep(0.02)
    assert not thread.is_alive()


def test_calibrates_a_participant_and_resumes(tmp_path):
    """A benchmark cell with TwoPointsDE on P1, cut short after its first batch, resumes by replay to the same run."""
    from wrist_env.bench.calibrate import calibrate
    from wrist_env.bench.log import RunLog
    from wrist_env.bench.schema import RunKey
    from wrist_env.runs import provenance

    options = {"batch_size": 3}
    full = calibrate("P1", "ng-twopointsde", budget=6, seed=2, log=tmp_path / "full", options=options)
    assert full.result.nfev == 6 and np.isfinite(full.cost)
    key = RunKey("P1", "ng-twopointsde", 2, 6)
    first = RunLog(tmp_path / "full").read_cell(key).iloc[:3]
    columns = lambda prefix: first[[c for c in first.columns if c.startswith(prefix)]].to_numpy()  # noqa: E731
    made_from = provenance.of_participant("P1")  # what the cut log was made on, as calibrate records it
    RunLog(tmp_path / "cut").append(
        key,
        0,
        0,
        columns("x."),
        first["cost"].to_numpy(),
        first["failed"].to_numpy(),
        columns("rmse."),
        made_from=made_from,
    )
    resumed = calibrate("P1", "ng-twopointsde", budget=6, seed=2, log=tmp_path / "cut", options=options)
    assert resumed.replayed == 3
    np.testing.assert_array_equal(resumed.result.history_fun, full.result.history_fun)
