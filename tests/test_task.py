"""`Task`: a batch's `Evaluations` are the single evaluations, as arrays and one by one."""

import numpy as np
import pytest

from wrist_env import design
from wrist_env.errors import DesignError
from wrist_env.task import Evaluations, task


def test_a_batch_of_actions_is_its_rows_evaluated_one_at_a_time():
    calibrate = task("P1", "calibrate")
    actions = np.random.default_rng(4).uniform(-0.8, 0.8, (3, design.N_DESIGN))
    batch = calibrate.evaluate_actions(actions)
    single = [calibrate.evaluate_action(a) for a in actions]
    assert isinstance(batch, Evaluations) and len(batch) == 3 and batch.failed.dtype == bool
    np.testing.assert_array_equal(batch.cost, [e.cost for e in single])
    np.testing.assert_array_equal(batch.reward, -batch.cost)
    np.testing.assert_array_equal(batch.failed, [e.failed for e in single])
    for e, one in zip(batch, single):
        np.testing.assert_array_equal(e.result.poses, one.result.poses)
    assert batch[-1].cost == batch.cost[2] and [e.cost for e in batch[1:]] == list(batch.cost[1:])


def test_a_bad_row_or_shape_is_named():
    actions = np.zeros((3, design.N_DESIGN))
    actions[2, 5] = np.nan
    with pytest.raises(DesignError, match=rf"row 2 of the actions: .*{design.NAMES[5]}=nan"):
        task("P1", "calibrate").evaluate_actions(actions)
    with pytest.raises(DesignError, match=r"shape \(n, 27\), but got \(27,\)"):
        design.from_actions(np.zeros(design.N_DESIGN))
    assert design.from_actions(np.zeros((0, design.N_DESIGN))) == []


def test_without_a_reference_the_info_has_the_same_keys_as_none():
    """`outputs` without a cost report (a folder participant's idealized sweep) gives the keys a scored run
    gives, the cost's (`REFERENCE_KEYS`) None: not missing (a KeyError in `sensitivity`), not 0 (a perfect
    fit), not NaN (the info is JSON-ready)."""
    from wrist_env.task import REFERENCE_KEYS, outputs

    scored = task("P1", "calibrate").evaluate_action(np.zeros(design.N_DESIGN))
    unscored = outputs(scored.result)
    assert set(REFERENCE_KEYS) <= set(scored.info) and scored.info["error_p75"]["scaphoid"]
    assert set(unscored) == set(scored.info)
    assert all(unscored[k] is None for k in REFERENCE_KEYS)


def _unbuilt_task():
    """A Task with no model: an empty batch must not reach one."""
    from wrist_env.task import Task

    return Task.__new__(Task)


def test_an_empty_batch_is_empty_evaluations_of_the_right_shape():
    """`evaluate_batch([])` and `evaluate_actions` of shape (0, 27) simulate nothing and return empty arrays."""
    t = _unbuilt_task()
    for batch in (t.evaluate_batch([]), t.evaluate_actions(np.zeros((0, design.N_DESIGN)))):
        assert isinstance(batch, Evaluations) and len(batch) == 0 and list(batch) == []
        assert batch.cost.shape == batch.reward.shape == batch.failed.shape == (0,) and batch.failed.dtype == bool
    with pytest.raises(DesignError, match=r"shape \(n, 27\), but got \(0, 26\)"):
        t.evaluate_actions(np.zeros((0, 26)))


def test_a_batch_item_that_is_not_a_design_is_named():
    with pytest.raises(DesignError, match="item 1 of the designs is a ndarray, not a Design"):
        _unbuilt_task().evaluate_batch([design.population(), np.zeros(design.N_DESIGN)])
