"""The Gymnasium environments: Gymnasium's own checker, the native vector env, the cost at truth."""

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import wrist_env
from wrist_env import design
from wrist_env.envs.wrappers import FreezeVariables
from wrist_env.model import TRAPEZIUM
from wrist_env.participants import builtin
from wrist_env.solver.settings import DEFAULT_LOADS
from wrist_env.task import task

IDS = wrist_env.registered_ids()


def test_every_builtin_participant_has_three_ids():
    for name in builtin.BUILTIN:
        for motion in ("Calibrate", "Validate", "Idealized"):
            assert f"wrist_env/{motion}-{name}-v0" in IDS


@pytest.mark.parametrize("env_id", IDS)
def test_check_env(env_id):
    env = gym.make(env_id)
    check_env(env.unwrapped, skip_render_check=True)
    obs, _ = env.reset(seed=1)
    _, reward, terminated, truncated, info = env.step(np.zeros(27, dtype=np.float32))
    assert terminated and not truncated
    assert np.isfinite(reward) and not info["failed"]


def test_vector_entry_point_matches_single_steps():
    rng = np.random.default_rng(0)
    actions = rng.uniform(-0.6, 0.6, (8, 27)).astype(np.float32)
    vec = gym.make_vec("wrist_env/Calibrate-P1-v0", num_envs=8, vectorization_mode="vector_entry_point")
    vec.reset(seed=0)
    _, rewards, terminated, _, infos = vec.step(actions)
    assert terminated.all()
    env = gym.make("wrist_env/Calibrate-P1-v0")
    single = []
    for a in actions:
        env.reset(seed=0)
        single.append(env.step(a)[1])
    np.testing.assert_array_equal(rewards, single)
    assert infos["failed"].shape == (8,)


@pytest.mark.parametrize("name", builtin.BUILTIN)
def test_truth_beats_population_but_is_not_perfect(name):
    calibrate = task(name, "calibrate")
    at_truth = calibrate.evaluate(builtin.truth(name)).cost
    at_population = calibrate.evaluate(design.population()).cost
    assert 0.1 < at_truth < at_population, (at_truth, at_population)


def test_idealized_reward_is_zero_at_truth():
    """The idealized task's reference is the hidden truth's own sweep: the truth scores exactly 0."""
    evaluation = task("P1", "idealized").evaluate(builtin.truth("P1"))
    assert evaluation.cost < 1e-9 and not evaluation.failed


def test_out_of_range_action_is_a_clear_error():
    env = gym.make("wrist_env/Calibrate-P1-v0")
    env.reset()
    bad = np.zeros(27, dtype=np.float32)
    bad[2] = 1.5
    with pytest.raises(ValueError, match="SLIL_d.stiffness=1.5"):
        env.step(bad)
    with pytest.raises(ValueError, match=r"shape \(27,\)"):
        env.step(np.zeros(26))


def test_freeze_wrapper_keeps_ligaments_intact():
    env = FreezeVariables(gym.make("wrist_env/Calibrate-P1-v0"))
    assert env.action_space.shape == (22,)
    full = env.action(np.full(22, -1.0, dtype=np.float32))
    assert np.all(full[22:] == 1.0) and np.all(full[:22] == -1.0)
    env.reset()
    _, reward, terminated, _, info = env.step(np.zeros(22, dtype=np.float32))
    expected = task("P1", "calibrate").evaluate(design.population())
    assert reward == expected.reward


def test_a_failed_run_gives_the_same_nan_free_info_single_and_vectorized():
    """Failed runs (dislocated random designs) report zeros, never NaN or None, in the single env and
    in the vector env, whether the batch's first run failed or a later one."""
    pool = np.random.default_rng(11).uniform(-1, 1, (64, 27))
    single = gym.make("wrist_env/Idealized-P1-v0")
    single.reset(seed=0)
    pool_infos = [single.step(a)[4] for a in pool]
    failed = [i for i, info in enumerate(pool_infos) if info["failed"]]
    ok = [i for i, info in enumerate(pool_infos) if not info["failed"]]
    assert len(failed) >= 2 and len(ok) >= 2, failed
    pick = [ok[0], failed[0], failed[1], ok[1]]
    actions = pool[pick]
    infos = [pool_infos[i] for i in pick]
    for order in ([0, 1, 2, 3], [1, 0, 2, 3]):
        vec = gym.make_vec("wrist_env/Idealized-P1-v0", num_envs=4, vectorization_mode="vector_entry_point")
        vec.reset(seed=0)
        _, rewards, _, _, vinfo = vec.step(actions[order])
        for k, i in enumerate(order):
            for key in ("error_p75", "rmse", "cost_terms"):
                for bone, dofs in infos[i][key].items():
                    for dof, value in dofs.items():
                        assert value is not None and np.isfinite(value), (key, bone, dof, value)
                        got = vinfo[key][bone][dof][k]
                        assert np.asarray(vinfo[key][bone][dof]).dtype == np.float64 and got == value, (key, got, value)


@pytest.mark.parametrize("num_envs", [0, -1, 10**9])
def test_a_vector_env_size_out_of_bounds_is_refused_before_the_model_loads(num_envs):
    from wrist_env.errors import InputError

    with pytest.raises(InputError, match=rf"num_envs must be an integer in \[1, 4,096\], but got {num_envs}"):
        gym.make_vec("wrist_env/Calibrate-P1-v0", num_envs=num_envs, vectorization_mode="vector_entry_point")


@pytest.mark.parametrize("bad", [np.nan, 3.0])
def test_a_bad_row_of_a_vector_action_is_named(bad):
    from wrist_env.errors import DesignError

    env = gym.make_vec("wrist_env/Calibrate-P1-v0", num_envs=3, vectorization_mode="vector_entry_point")
    actions = np.zeros((3, design.N_DESIGN))
    actions[1, 4] = bad
    with pytest.raises(DesignError, match=rf"row 1 of the actions: .*{design.NAMES[4]}={bad}"):
        env.step(actions)


def test_the_idealized_sweep_under_the_tendons_load_is_its_own_task():
    """`load_direction` reaches the sweep's driver through `gym.make`: the tendons' lines move the
    truth's radioscaphoid pressure, the reward stays 0 at the truth under either load; an unknown load
    is refused."""
    truth = design.to_action(builtin.truth("P1"))
    rs = {}
    for direction in ("axial", "erhart2020"):
        env = gym.make("wrist_env/Idealized-P1-v0", load_direction=direction)
        env.reset(seed=0)
        _, reward, *_, info = env.step(truth)
        assert reward == pytest.approx(0.0, abs=1e-9), (direction, reward)
        rs[direction] = info["contact"]["radioscaphoid"]["mean_pressure_mpa"]
        lines = env.unwrapped.task.driver.loads
        assert lines.name == direction and len(lines.share) == (1 if direction == "axial" else 16), lines
    assert np.abs(rs["axial"] - rs["erhart2020"]).max() > 0.01, rs
    with pytest.raises(ValueError, match="load_direction"):
        task("P1", "calibrate", "upward")


@pytest.mark.parametrize("motion", ["calibrate", "validate"])
def test_a_trial_loads_the_radial_column_as_its_truth_run_did(motion):
    """In a trial the capitate is prescribed and the radial column is free under the default tendon lines
    at the trial's recorded total load per frame (`Trial.load_n`, the truth run's)."""
    t = task("P1", motion)
    trial = builtin.trials("P1")["unresisted" if motion == "calibrate" else "resisted"]
    assert t.load_direction == DEFAULT_LOADS and t.driver.loads.name == DEFAULT_LOADS
    np.testing.assert_array_equal(t.driver.load_n, trial.load_n)
    assert trial.load_n.min() >= 10.0 and TRAPEZIUM in t.driver.loads.body
