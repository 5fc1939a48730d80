"""Resume by replay (`bench.replay.Replayed`) on its own: toy calibrators over a cheap function, no simulation."""

import numpy as np
import pytest

import optimizers
from wrist_env.bench.replay import REPLAY_TOLERANCE, Logged, Replayed, ResumeError

DIM, BUDGET, CELL = 3, 40, "P1.cmaes.seed1.budget40"


def sphere(x):
    return np.sum((np.asarray(x) - 0.3) ** 2, axis=1)


class Counted:
    """`sphere`, keeping every point it is asked to evaluate."""

    def __init__(self):
        self.points = []

    def __call__(self, x):
        self.points.extend(np.asarray(x))
        return sphere(x)


def run(name, seed=1, budget=BUDGET):
    """The uninterrupted run: its result and its batches [(x, y)] in order."""
    batches = []
    result = optimizers.minimize(
        optimizers.make(name, dim=DIM, budget=budget, seed=seed), sphere, lambda x, y: batches.append((x, y))
    )
    return result, batches


def logged(batches):
    return Logged(np.concatenate([x for x, _ in batches]), np.concatenate([y for _, y in batches]), len(batches))


@pytest.mark.parametrize("name", ["cmaes", "random", "nelder-mead"])
def test_a_replayed_run_ends_as_the_uninterrupted_one_without_evaluating_the_logged_points(name):
    full, batches = run(name)
    cut = len(batches) // 2
    log = logged(batches[:cut])
    seen = []
    resumed = Replayed(optimizers.make(name, dim=DIM, budget=BUDGET, seed=1), log, CELL, lambda x, y: seen.append(x))
    assert resumed.replayed == len(log.y) > 0 and resumed.nfev == len(log.y) and len(seen) == cut
    counted = Counted()
    result = optimizers.minimize(resumed, counted)
    np.testing.assert_array_equal(result.history_x, full.history_x)
    np.testing.assert_array_equal(result.history_fun, full.history_fun)
    np.testing.assert_array_equal(result.x, full.x)
    assert len(counted.points) == BUDGET - len(log.y)  # only what was not logged is evaluated
    np.testing.assert_array_equal(np.array(counted.points), full.history_x[len(log.y) :])


def test_the_calibrator_is_told_the_logged_values_not_recomputed_ones():
    _, batches = run("cmaes")
    log = logged(batches[:2])
    told = Logged(log.x, log.y + 1.0, log.batches)  # e.g. a MAP objective: not what `sphere` gives
    result = optimizers.minimize(Replayed(optimizers.make("cmaes", dim=DIM, budget=BUDGET, seed=1), told, CELL), sphere)
    np.testing.assert_array_equal(result.history_fun[: len(log.y)], log.y + 1.0)


def test_nothing_logged_passes_through():
    full, _ = run("cmaes")
    resumed = Replayed(optimizers.make("cmaes", dim=DIM, budget=BUDGET, seed=1), Logged.of(None, DIM), CELL)
    assert resumed.replayed == 0
    np.testing.assert_array_equal(optimizers.minimize(resumed, sphere).history_x, full.history_x)


def test_a_calibrator_that_asks_otherwise_cannot_resume():
    _, batches = run("cmaes")
    with pytest.raises(ResumeError, match=rf"^{CELL}: on resume the calibrator asked for evaluations 0…6 differently"):
        Replayed(optimizers.make("cmaes", dim=DIM, budget=BUDGET, seed=2), logged(batches[:2]), CELL)


def test_points_within_the_tolerance_replay_and_beyond_it_do_not():
    _, batches = run("cmaes")
    log = logged(batches[:2])
    near = Logged(log.x + 0.5 * REPLAY_TOLERANCE, log.y, log.batches)
    assert Replayed(optimizers.make("cmaes", dim=DIM, budget=BUDGET, seed=1), near, CELL).replayed == len(log.y)
    far = Logged(log.x + 3 * REPLAY_TOLERANCE, log.y, log.batches)
    with pytest.raises(ResumeError, match="differently"):
        Replayed(optimizers.make("cmaes", dim=DIM, budget=BUDGET, seed=1), far, CELL)


def test_a_batch_reaching_past_the_log_cannot_resume():
    _, batches = run("cmaes")  # batches of 7
    log = logged(batches[:2])
    partial = Logged(log.x[:10], log.y[:10], 2)
    with pytest.raises(ResumeError, match=rf"{CELL}: .* evaluations 7…13 differently than logged \(10 logged\)"):
        Replayed(optimizers.make("cmaes", dim=DIM, budget=BUDGET, seed=1), partial, CELL)


def test_more_logged_than_the_budget_cannot_resume():
    _, batches = run("random", budget=BUDGET)
    with pytest.raises(ResumeError, match=rf"{CELL}: 40 evaluations are logged, more than the budget 32"):
        Replayed(optimizers.make("random", dim=DIM, budget=32, seed=1), logged(batches), CELL)


class _StopsAtFour(optimizers.Optimizer):
    """Proposes one seeded point a batch and has nothing more after four."""

    name = "test-stops-at-four"

    def _ask(self, n_max):
        return self.rng.uniform(-1, 1, (1, self.dim))

    def _stopped(self):
        return self.nfev >= 4


def test_a_calibrator_that_stops_before_the_end_of_the_log_cannot_resume():
    batches = []
    optimizers.minimize(_StopsAtFour(DIM, 8, seed=0), sphere, lambda x, y: batches.append((x, y)))
    log = logged(batches)
    log = Logged(np.vstack([log.x, log.x[:2]]), np.concatenate([log.y, log.y[:2]]), 6)
    with pytest.raises(ResumeError, match=rf"{CELL}: the calibrator stopped after 4 evaluations, but 6 are logged"):
        Replayed(_StopsAtFour(DIM, 8, seed=0), log, CELL)
