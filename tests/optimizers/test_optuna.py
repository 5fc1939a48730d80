"""Optuna's samplers as calibrators: exact budget, seeded, batches, SQLite storage and resuming."""

import math

import numpy as np
import optuna
import pytest

import optimizers
from optimizers.base import prior_draw
from optimizers.optuna_samplers import HAS_TORCH

needs_torch = pytest.mark.skipif(not HAS_TORCH, reason="optuna-gp needs PyTorch, which is not installed")
SAMPLERS = ["optuna-tpe", "optuna-cmaes", pytest.param("optuna-gp", marks=needs_torch)]


def sphere(x):
    return np.sum((x - 0.25) ** 2, axis=1)


def run(name, budget, seed=0, dim=3, fun=sphere, **options):
    opt = optimizers.make(
        name,
        dim,
        budget,
        seed=seed,
        lower=[-1.0, 0.0, 2.0][:dim] + [-1.0] * max(0, dim - 3),
        upper=[1.0, 0.5, 3.0][:dim] + [1.0] * max(0, dim - 3),
        **options,
    )
    sizes = []
    res = optimizers.minimize(opt, fun, callback=lambda x, y: sizes.append(len(x)))
    return opt, res, sizes


def test_registered_as_available():
    names = optimizers.available()
    assert {"optuna-tpe", "optuna-cmaes"} <= set(names)
    assert ("optuna-gp" in names) == HAS_TORCH


@pytest.mark.skipif(HAS_TORCH, reason="PyTorch is installed: optuna-gp is available")
def test_optuna_gp_without_torch_names_the_extra():
    with pytest.raises(optimizers.UnknownOptimizerError, match=r"needs PyTorch.*\[gp\]"):
        optimizers.make("optuna-gp", 3, 10)


@pytest.mark.parametrize("name", SAMPLERS)
@pytest.mark.parametrize("budget", [1, 5, 17])
def test_budget_exact_and_bounds(name, budget):
    opt, res, sizes = run(name, budget)
    assert res.nfev == budget == sum(sizes) == len(opt.study.trials)
    assert all(t.state == optuna.trial.TrialState.COMPLETE for t in opt.study.trials)
    assert np.all(res.history_x >= opt.lower) and np.all(res.history_x <= opt.upper)
    # the study holds exactly what was evaluated
    told = np.array([[t.params[f"x{i}"] for i in range(3)] for t in opt.study.trials])
    np.testing.assert_array_equal(told, res.history_x)
    np.testing.assert_array_equal([t.value for t in opt.study.trials], res.history_fun)


@pytest.mark.parametrize("name", SAMPLERS)
def test_seeded(name):
    a = run(name, 20, seed=1)[1]
    b = run(name, 20, seed=1)[1]
    c = run(name, 20, seed=2)[1]
    np.testing.assert_array_equal(a.history_x, b.history_x)
    assert not np.array_equal(a.history_x, c.history_x)


@pytest.mark.parametrize(
    "name, batch",
    [
        ("optuna-tpe", 8),
        ("optuna-cmaes", 4 + math.floor(3 * math.log(3))),
        pytest.param("optuna-gp", 1, marks=needs_torch),
    ],
)
def test_default_batches(name, batch):
    sizes = run(name, 20)[2]
    assert sizes[:-1] == [batch] * (len(sizes) - 1) and 1 <= sizes[-1] <= batch


def test_batch_size_option():
    assert run("optuna-tpe", 10, batch_size=3)[2] == [3, 3, 3, 1]


def test_cmaes_improves_past_its_start():
    """One generation per batch: CMA-ES updates between batches and closes in on the minimum."""
    centre = np.array([0.1, 0.3, 2.6, -0.2, 0.1])  # inside the box run() gives
    box_centre = [0.0, 0.25, 2.5, 0.0, 0.0]  # a start far from the minimum, not the seed's draw
    res = run("optuna-cmaes", 200, dim=5, fun=lambda x: np.sum((x - centre) ** 2, axis=1), x0=box_centre)[1]
    first = res.history_fun[:8].min()
    assert res.fun < 1e-2 * first


def test_cmaes_starts_at_the_seeds_draw_from_the_prior():
    """Optuna's default start, the box centre, would start every seed at the population design."""
    starts = [optimizers.make("optuna-cmaes", 3, 10, seed=s).study.sampler._x0 for s in (4, 5)]
    draw = prior_draw(np.random.default_rng(4), -np.ones(3), np.ones(3))
    assert starts[0] == dict(zip(["x0", "x1", "x2"], draw.tolist()))
    assert starts[0] != starts[1]


def test_failed_evaluations_are_told_as_inf():
    def fails(x):
        return np.where(x[:, 0] > 0.5, np.nan, sphere(x))

    opt, res, _ = run("optuna-tpe", 30, fun=fails)
    values = [t.value for t in opt.study.trials]
    assert len(values) == 30 and math.inf in values and np.isfinite(res.fun)


@pytest.mark.parametrize("name", SAMPLERS)
def test_sqlite_storage_and_resume(name, tmp_path):
    url = f"sqlite:///{tmp_path / 'studies.db'}"
    first = run(name, 10, storage=url, study_name="P1")[1]
    study = optuna.load_study(study_name="P1", storage=url)
    assert len(study.trials) == 10 and all(t.state == optuna.trial.TrialState.COMPLETE for t in study.trials)
    assert [t.value for t in study.trials] == first.history_fun.tolist()
    # a new optimizer with the same storage and name continues the study: its budget counts its own trials
    opt, second, _ = run(name, 7, seed=1, storage=url, study_name="P1")
    assert second.nfev == 7
    study = optuna.load_study(study_name="P1", storage=url)
    assert len(study.trials) == 17 and [t.number for t in study.trials] == list(range(17))
    assert [t.value for t in study.trials][10:] == second.history_fun.tolist()
    assert study.best_value == min(first.fun, second.fun)
    # other names in the same file are separate studies
    run(name, 3, storage=url, study_name="P2")
    assert len(optuna.load_study(study_name="P2", storage=url).trials) == 3


@pytest.mark.parametrize("name", ["optuna-tpe", "optuna-cmaes"])
def test_journal_file_storage(name, tmp_path):
    """A path without a scheme is a journal file; the same seed gives the same run as in memory."""
    path = tmp_path / "studies.log"
    a = run(name, 12, storage=str(path), study_name="P1")[1]
    run(name, 5, storage=path, study_name="P1")
    study = optuna.load_study(
        study_name="P1", storage=optuna.storages.JournalStorage(optuna.storages.journal.JournalFileBackend(str(path)))
    )
    assert len(study.trials) == 17
    np.testing.assert_array_equal(a.history_x, run(name, 12)[1].history_x)


def test_in_memory_by_default():
    opt = run("optuna-tpe", 3)[0]
    assert isinstance(opt.study._storage, optuna.storages.InMemoryStorage)
