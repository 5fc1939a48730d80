"""Calibrators that take a start point start where their seed puts it: a draw from the prior (issue 55)."""

import numpy as np
import pytest

import optimizers
from optimizers.base import prior_draw
from wrist_env.design import N_MATERIAL
from wrist_env.table2 import sample_materials

LOWER, UPPER = -np.ones(N_MATERIAL), np.ones(N_MATERIAL)


def first_point(name: str, seed: int, **options) -> np.ndarray:
    opt = optimizers.make(name, dim=N_MATERIAL, budget=30, seed=seed, **options)
    try:
        return opt.ask()[0]
    finally:
        opt.close()


def test_nelder_mead_seeds_start_at_different_points():
    a, b = first_point("nelder-mead", 0), first_point("nelder-mead", 1)
    assert np.abs(a - b).max() > 0.01
    np.testing.assert_array_equal(first_point("nelder-mead", 1), b)


@pytest.mark.parametrize("seed", [0, 3])
def test_nelder_mead_starts_at_the_seeds_draw_from_the_prior(seed):
    """On the benchmark's box the start is `table2.sample_materials(1, seed)`, the draw instances use."""
    np.testing.assert_array_equal(first_point("nelder-mead", seed), sample_materials(1, seed)[0])


def test_cmaes_mean_starts_at_the_seeds_draw():
    opt = optimizers.make("cmaes", dim=N_MATERIAL, budget=30, seed=2)
    np.testing.assert_array_equal(opt.x0, sample_materials(1, 2)[0])
    np.testing.assert_allclose(opt.es.mean, opt.x0)


def test_an_explicit_x0_is_kept():
    np.testing.assert_array_equal(first_point("nelder-mead", 5, x0=np.zeros(N_MATERIAL)), np.zeros(N_MATERIAL))


def test_the_prior_draw_fills_an_asymmetric_box_around_its_centre():
    lower, upper = np.array([0.0, -5.0]), np.array([2.0, 15.0])
    draws = np.array([prior_draw(np.random.default_rng(s), lower, upper) for s in range(400)])
    assert np.all(draws >= lower) and np.all(draws <= upper)
    assert abs(draws[:, 0].mean() - 1.0) < 0.05 and abs(draws[:, 1].mean() - 5.0) < 0.5
    # SD one sixth of the width (a normal truncated at ±3 SD keeps 98.7 % of its SD)
    np.testing.assert_allclose(draws.std(axis=0), [2.0 / 6, 20.0 / 6], rtol=0.1)
