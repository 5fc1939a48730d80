"""Adapters don't cripple their libraries: ours reproduce `cma`, SciPy's Nelder–Mead and SciPy's LHS exactly.

10-D Rosenbrock in [-2, 2]^10, budget 2000. Neither library stops before
2000 evaluations there, so no restart happens and the comparison is of the
whole evaluation history, bit for bit — not just of the best value.
"""

import cma
import numpy as np
import pytest
from scipy.optimize import Bounds
from scipy.optimize import minimize as scipy_minimize
from scipy.stats import qmc

import optimizers
from optimizers.nelder_mead import initial_simplex

DIM, BUDGET = 10, 2000
LOWER, UPPER = -2.0 * np.ones(DIM), 2.0 * np.ones(DIM)


def rosenbrock(x) -> float:
    x = np.asarray(x, dtype=np.float64)
    return float(np.sum(100.0 * (x[1:] - x[:-1] ** 2) ** 2 + (1.0 - x[:-1]) ** 2))


def rosenbrock_batch(x):
    return np.array([rosenbrock(xi) for xi in x])


def sphere(x):
    return np.sum((np.atleast_2d(x) - 0.2) ** 2, axis=1)


def test_cmaes_matches_cma():
    # cma directly: the options our adapter documents, seed 0 → cma seed 1
    es = cma.CMAEvolutionStrategy(
        np.zeros(DIM).tolist(),
        0.3 * 4.0,
        {"bounds": [LOWER.tolist(), UPPER.tolist()], "seed": 1, "popsize": 10, "verbose": -9, "maxfevals": BUDGET},
    )
    xs, fs = [], []
    while len(fs) < BUDGET:
        assert not es.stop(), es.stop()  # cma would not stop (or restart) before the budget
        population = es.ask()
        values = [rosenbrock(x) for x in population]
        es.tell(population, values)
        xs.extend(population)
        fs.extend(values)

    opt = optimizers.make("cmaes", dim=DIM, budget=BUDGET, seed=0, lower=LOWER, upper=UPPER, x0=np.zeros(DIM))
    ours = optimizers.minimize(opt, rosenbrock_batch)

    assert opt.restarts == 0
    np.testing.assert_array_equal(ours.history_x, np.array(xs[:BUDGET]))
    np.testing.assert_array_equal(ours.history_fun, np.array(fs[:BUDGET]))
    assert ours.fun == min(fs[:BUDGET])
    assert ours.fun < 10.0  # Rosenbrock at the start (0) is 9; CMA-ES makes progress


def test_cmaes_runs_interleave_without_disturbing_each_other():
    """cma samples from NumPy's global random state; each adapter swaps in its own copy."""
    alone = [optimizers.minimize(optimizers.make("cmaes", dim=4, budget=120, seed=s), sphere) for s in (0, 1)]
    a, b = (optimizers.make("cmaes", dim=4, budget=120, seed=s) for s in (0, 1))
    np.random.seed(7)
    outside = np.random.rand()
    while not (a.done and b.done):
        for opt in (a, b):
            if not opt.done:
                x = opt.ask()
                np.random.rand(3)  # someone else using the global state in between
                opt.tell(x, sphere(x))
    for together, reference in zip((a.result(), b.result()), alone):
        np.testing.assert_array_equal(together.history_x, reference.history_x)
    np.random.seed(7)
    assert np.random.rand() == outside  # and the adapters leave the global state alone


def test_cmaes_restarts_with_a_doubled_population():
    opt = optimizers.make("cmaes", dim=2, budget=3000, seed=1)
    result = optimizers.minimize(opt, sphere)
    assert result.nfev == 3000
    assert opt.restarts >= 1 and opt.popsize == 6 * 2**opt.restarts
    assert result.fun < 1e-12


def test_cmaes_truncates_the_last_population():
    opt = optimizers.make("cmaes", dim=5, budget=20, seed=0)  # popsize 8: batches 8, 8, 4
    sizes = []
    while not opt.done:
        x = opt.ask()
        sizes.append(len(x))
        opt.tell(x, sphere(x))
    assert sizes == [8, 8, 4]
    assert opt.es.countevals == 16  # the truncated batch is recorded but not told to cma


def test_nelder_mead_matches_scipy():
    simplex = initial_simplex(np.zeros(DIM), LOWER, UPPER, 0.25)
    evaluated = []

    def fun(x):
        evaluated.append(rosenbrock(x))
        return evaluated[-1]

    reference = scipy_minimize(
        fun,
        np.zeros(DIM),
        method="Nelder-Mead",
        bounds=Bounds(LOWER, UPPER),
        options={"maxfev": BUDGET, "initial_simplex": simplex},
    )
    assert reference.nfev == BUDGET and not reference.success  # SciPy's run uses the whole budget

    ours = optimizers.minimize(
        optimizers.make("nelder-mead", dim=DIM, budget=BUDGET, seed=0, lower=LOWER, upper=UPPER, x0=np.zeros(DIM)),
        rosenbrock_batch,
    )
    np.testing.assert_array_equal(ours.history_fun, evaluated)
    assert ours.fun == reference.fun
    np.testing.assert_array_equal(ours.x, reference.x)


def test_nelder_mead_restarts():
    """In 2-D SciPy converges long before 400 evaluations: our first run is SciPy's, then restarts fill the budget."""
    evaluated = []

    def fun(x):
        evaluated.append(sphere(x)[0])
        return evaluated[-1]

    lower, upper = -np.ones(2), np.ones(2)
    reference = scipy_minimize(
        fun,
        np.zeros(2),
        method="Nelder-Mead",
        bounds=Bounds(lower, upper),
        options={"maxfev": 400, "initial_simplex": initial_simplex(np.zeros(2), lower, upper)},
    )
    assert reference.success and reference.nfev < 200
    n = reference.nfev

    a, b = (
        optimizers.minimize(optimizers.make("nelder-mead", dim=2, budget=400, seed=s, x0=np.zeros(2)), sphere)
        for s in (0, 1)
    )
    for result in (a, b):
        assert result.nfev == 400
        np.testing.assert_array_equal(result.history_fun[:n], evaluated)  # the first run is SciPy's
        assert result.fun <= reference.fun
    # from the same x0, the restarts start from random points drawn from the seeded rng
    np.testing.assert_array_equal(a.history_x[:n], b.history_x[:n])
    assert not np.array_equal(a.history_x[n], b.history_x[n])


@pytest.mark.parametrize("restart", ["random", "best"])
def test_nelder_mead_restart_options(restart):
    opt = optimizers.make("nelder-mead", dim=3, budget=500, seed=2, restart=restart)
    result = optimizers.minimize(opt, sphere)
    assert result.nfev == 500 and result.fun < 1e-8
    assert not opt._bridge.thread.is_alive()


def test_nelder_mead_thread_ends_when_abandoned_or_closed():
    opt = optimizers.make("nelder-mead", dim=3, budget=100, seed=0)
    opt.tell(opt.ask(), [1.0])
    thread = opt._bridge.thread
    opt.close()
    assert not thread.is_alive()
    with pytest.raises(RuntimeError):
        opt.ask()

    opt = optimizers.make("nelder-mead", dim=3, budget=100, seed=0)
    opt.ask()
    thread = opt._bridge.thread
    del opt  # mid-evaluation: __del__ unblocks the worker
    thread.join(timeout=5)
    assert not thread.is_alive()


def test_lhs_is_scipys_design():
    budget = 50
    lower, upper = np.array([-1.0, -2.0, 0.0]), np.array([1.0, 0.5, 3.0])
    opt = optimizers.make("lhs", dim=3, budget=budget, seed=5, lower=lower, upper=upper, batch_size=16)
    sizes = []
    while not opt.done:
        x = opt.ask()
        sizes.append(len(x))
        opt.tell(x, sphere(x))
    assert sizes == [16, 16, 16, 2]
    design = qmc.scale(qmc.LatinHypercube(3, rng=np.random.default_rng(5)).random(budget), lower, upper)
    np.testing.assert_array_equal(opt.result().history_x, design)
    # one point in each of the `budget` strata of every coordinate
    strata = np.floor((design - lower) / (upper - lower) * budget).astype(int)
    for column in strata.T:
        assert sorted(column) == list(range(budget))
