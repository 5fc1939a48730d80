"""The surrogate calibrator: beats random search, its polish helps, the budget is exact."""

import threading

import numpy as np
import pytest

import optimizers
from optimizers.surrogate import Surrogate


def quadratic(x):
    return np.sum((x - 0.3) ** 2, axis=1)


def rosenbrock(x):
    return np.sum(100.0 * (x[:, 1:] - x[:, :-1] ** 2) ** 2 + (1.0 - x[:, :-1]) ** 2, axis=1)


def run(name, fun, dim=5, budget=150, seed=0, lower=-1.0, upper=1.0, **options):
    opt = optimizers.make(name, dim, budget, seed=seed, lower=lower, upper=upper, **options)
    sizes = []
    res = optimizers.minimize(opt, fun, callback=lambda x, y: sizes.append(len(x)))
    return opt, res, sizes


@pytest.mark.parametrize("seed", [0, 1, 2])
@pytest.mark.parametrize(
    "fun, lower, upper", [(quadratic, -1.0, 1.0), (rosenbrock, -2.0, 2.0)], ids=["quadratic", "rosenbrock"]
)
def test_beats_random_search(fun, lower, upper, seed):
    _, surrogate, _ = run("surrogate", fun, seed=seed, lower=lower, upper=upper)
    _, random, _ = run("random", fun, seed=seed, lower=lower, upper=upper)
    assert surrogate.nfev == random.nfev == 150
    assert surrogate.fun < 0.1 * random.fun


def test_registered():
    assert "surrogate" in optimizers.available()
    assert optimizers.get("surrogate") is Surrogate


@pytest.mark.parametrize(
    "fun, lower, upper", [(quadratic, -1.0, 1.0), (rosenbrock, -2.0, 2.0)], ids=["quadratic", "rosenbrock"]
)
def test_polish_reduces_the_best_value(fun, lower, upper):
    opt, res, sizes = run("surrogate", fun, lower=lower, upper=upper)
    assert len(opt.polish_log) == 1
    log = opt.polish_log[0]
    assert log["nfev_start"] == 150 - opt.polish_budget == 105
    assert log["fun_end"] < log["fun_start"]
    # the polish asks for whole finite-difference gradients: dim points (centre known) or dim + 1
    ends = np.cumsum(sizes)
    polish = [k for k, end in zip(sizes, ends) if log["nfev_start"] < end <= log["nfev_end"]]
    assert polish and set(polish) <= {5, 6}
    assert polish[0] == 5  # starts at the best point, whose value is known
    # and the finite-difference points sit one step (1e-3 box widths) from their centre
    first = res.history_x[log["nfev_start"] : log["nfev_start"] + 5]
    centre = res.history_x[int(np.argmin(res.history_fun[: log["nfev_start"]]))]
    np.testing.assert_allclose(np.abs(first - centre).sum(axis=1), 1e-3 * (upper - lower), rtol=1e-9)


def test_polish_can_be_switched_off():
    opt, res, sizes = run("surrogate", quadratic, polish_fraction=0.0)
    assert opt.polish_log == [] and res.nfev == 150
    assert max(sizes[1:]) <= 4


@pytest.mark.parametrize("budget", [1, 2, 6, 7, 10, 23, 33, 151])
def test_budget_exact_bounds_and_no_thread_left(budget):
    before = threading.active_count()
    opt, res, sizes = run(
        "surrogate", quadratic, dim=5, budget=budget, lower=[-1, -2, 0, 0, 3], upper=[1, 0, 0.5, 10, 4]
    )
    assert res.nfev == budget == sum(sizes) == len(res.history_fun)
    assert np.all(res.history_x >= opt.lower) and np.all(res.history_x <= opt.upper)
    assert threading.active_count() == before


def test_seeded():
    a = run("surrogate", rosenbrock, budget=60, seed=3)[1]
    b = run("surrogate", rosenbrock, budget=60, seed=3)[1]
    c = run("surrogate", rosenbrock, budget=60, seed=4)[1]
    np.testing.assert_array_equal(a.history_x, b.history_x)
    assert not np.array_equal(a.history_x, c.history_x)


def test_failed_evaluations_far_from_the_optimum():
    """NaN (a failed simulation) costs only those points: the surrogate learns to stay away."""

    def fails_in_a_corner(x):
        return np.where(x[:, 0] + x[:, 1] < -0.8, np.nan, quadratic(x))

    _, res, _ = run("surrogate", fails_in_a_corner, budget=120)
    assert res.nfev == 120 and res.fun < 1e-4
    assert np.isinf(res.history_fun).any()


def test_failed_evaluations_in_the_polish():
    """Failures right past the optimum hit the gradient batches and line search: still a sound run."""

    def fails_past_the_optimum(x):
        return np.where(x[:, 0] > 0.305, np.nan, quadratic(x))

    opt, res, _ = run("surrogate", fails_past_the_optimum, budget=120)
    log = opt.polish_log[0]
    assert res.nfev == 120 and np.isfinite(res.fun) and log["fun_end"] <= log["fun_start"]
    assert np.isinf(res.history_fun[log["nfev_start"] : log["nfev_end"]]).any()
    random = run("random", fails_past_the_optimum, budget=120)[1]
    assert res.fun < 0.2 * random.fun


def test_close_mid_polish():
    opt = optimizers.make("surrogate", 5, 150, seed=0)
    while not opt.polish_log:
        x = opt.ask()
        opt.tell(x, quadratic(x))
    opt.ask()  # a gradient batch the thread now waits for
    opt.close()
    assert opt._bridge is None and opt.polish_log[0]["message"] == "closed"


def test_rejects_bad_options():
    with pytest.raises(ValueError):
        Surrogate(3, 50, fd_step=0.0)
    with pytest.raises(ValueError):
        Surrogate(3, 50, polish_fraction=1.5)
