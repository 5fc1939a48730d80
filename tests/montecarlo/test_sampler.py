"""Monte Carlo draws (no simulation): tear rates, Latin-hypercube strata, truncated normals, seeds, rounds."""

import numpy as np
import pytest
from scipy import stats as sps

from wrist_env import design
from wrist_env.errors import DesignError
from wrist_env.montecarlo import sampler
from wrist_env.montecarlo.config import StudyConfig
from wrist_env.montecarlo.study import _chunks, _plan


def test_tear_rate_is_0_3_and_tears_are_independent():
    a = sampler.block_actions(0, "P1", 0, 2000)
    torn = a[:, design.N_MATERIAL :] < 0
    assert set(np.unique(a[:, design.N_MATERIAL :])) == {sampler.TORN_ACTION, sampler.INTACT_ACTION}
    assert np.all(np.abs(torn.mean(axis=0) - 0.3) <= 0.02), torn.mean(axis=0)
    for i in range(5):
        for j in range(i + 1, 5):
            assert abs((torn[:, i] & torn[:, j]).mean() - 0.09) <= 0.02
    assert abs((~torn).all(axis=1).mean() - 0.7**5) <= 0.02  # all intact


def test_each_latin_hypercube_stratum_is_hit_once_per_dimension():
    n = 500
    u = sampler.latin_hypercube(n, np.random.SeedSequence(3))
    assert u.shape == (n, design.N_DESIGN)
    for k in range(design.N_DESIGN):
        assert np.array_equal(np.sort(np.floor(u[:, k] * n).astype(int)), np.arange(n))
    # the same strata survive the truncated-normal inverse CDF, in the actions of a block
    a = sampler.block_actions(7, "P2", 3, n)
    back = sps.truncnorm.cdf(a[:, : design.N_MATERIAL] * design.SPAN_SD, -3, 3)
    for k in range(design.N_MATERIAL):
        assert np.array_equal(np.sort(np.floor(back[:, k] * n + 1e-9).astype(int)), np.arange(n))


def test_materials_follow_table2_normals_truncated_at_3_sd():
    a = sampler.block_actions(1, "P1", 0, 2000)
    m = a[:, : design.N_MATERIAL]
    assert m.min() >= -1.0 and m.max() <= 1.0
    for k in range(design.N_MATERIAL):
        assert sps.kstest(m[:, k] * design.SPAN_SD, sps.truncnorm(-3, 3).cdf).pvalue > 0.05
    physical = np.stack([design.from_action(x).vector for x in a[:50]])
    z = (physical[:, : design.N_MATERIAL] - design.MEAN[: design.N_MATERIAL]) / design.SD[: design.N_MATERIAL]
    assert np.allclose(z, m[:50] * design.SPAN_SD)


def test_blocks_are_seeded_by_seed_participant_and_block():
    a = sampler.block_actions(0, "P1", 0, 40)
    assert np.array_equal(a, sampler.block_actions(0, "P1", 0, 40))
    for other in (
        sampler.block_actions(1, "P1", 0, 40),
        sampler.block_actions(0, "P2", 0, 40),
        sampler.block_actions(0, "P1", 1, 40),
    ):
        assert not np.array_equal(a[:, : design.N_MATERIAL], other[:, : design.N_MATERIAL])
    with pytest.raises(ValueError):
        sampler.block_seed(-1, "P1", 0)


def test_unit_points_are_checked():
    with pytest.raises(DesignError):
        sampler.monte_carlo_from_unit(np.zeros((3, 26)))
    with pytest.raises(DesignError):
        sampler.monte_carlo_from_unit(np.full((3, 27), 1.5))
    with pytest.raises(DesignError):
        sampler.monte_carlo_from_unit(np.zeros((3, 27)), tear_probability=1.2)


def test_rounds_replace_excluded_and_failed_runs_with_fresh_blocks():
    config = StudyConfig(("P1",), n=5)
    rnd, counts = _plan("P1", config, {})
    assert (rnd.block, rnd.start, rnd.size, rnd.missing) == (0, 0, 5, (0, 1, 2, 3, 4))
    outcomes = {0: (True, False), 1: (True, True), 2: (False, False), 3: (True, False), 4: (True, False)}
    rnd, counts = _plan("P1", config, outcomes)
    assert (rnd.block, rnd.start, rnd.size, rnd.missing) == (1, 5, 2, (5, 6))
    assert (counts.attempts, counts.succeeded, counts.excluded, counts.failed) == (5, 3, 1, 1)
    outcomes.update({5: (True, False), 6: (False, False)})
    rnd, counts = _plan("P1", config, outcomes)
    assert (rnd.block, rnd.start, rnd.size) == (2, 7, 1)
    outcomes[7] = (True, False)
    rnd, counts = _plan("P1", config, outcomes)
    assert rnd is None and counts.succeeded == 5 and counts.attempts == 8 and counts.blocks == 3


def test_chunks_are_consecutive_and_bounded():
    assert list(_chunks((0, 1, 2, 3, 4, 7, 8, 10), 3)) == [(0, 1, 2), (3, 4), (7, 8), (10,)]
