"""Gymnasium environments: one step is one simulation of a 27-variable ligament design.

`reset` returns a fixed context observation (the population-mean design in
normalized units, zeros); `step(action)` maps the action in [-1, 1]^27 to a
design (`wrist_env.design`), simulates it and returns reward = −cost,
`terminated=True`. `WristVectorEnv` is the native batched form over
`simulate_batch`: a population of designs is one call.
"""

from __future__ import annotations

import gymnasium as gym
import numpy as np
from gymnasium.vector import AutoresetMode, VectorEnv
from numpy.typing import ArrayLike

from wrist_env import design
from wrist_env.limits import MAX_BATCH, check_int
from wrist_env.solver.settings import DEFAULT_LOADS
from wrist_env.task import task

OBSERVATION = np.zeros(design.N_DESIGN, dtype=np.float32)


def _spaces():
    box = gym.spaces.Box(-1.0, 1.0, (design.N_DESIGN,), dtype=np.float32)
    return box, gym.spaces.Box(-1.0, 1.0, (design.N_DESIGN,), dtype=np.float32)


class WristEnv(gym.Env):
    """Calibrate, validate or sweep one participant (see `wrist_env.task.Task`).

    participant: a registered participant name; motion: "calibrate",
    "validate" or "idealized"; load_direction: the idealized sweep's load
    (`settings.LOAD_DIRECTIONS`, default `settings.DEFAULT_LOADS`); instance: the problem instance of a
    built-in participant (`participants.instances`: 0, the default, its shipped truth and trials; k ≥ 1 a
    truth drawn from the prior, `gymnasium.make("wrist_env/Calibrate-P1-v0", instance=k)`). info: cost, per-DOF 75th-percentile errors and
    RMSE (mm, deg), per-frame contact (MPa, mm², N), bundle forces (N),
    energies (N·mm), poses, and `failed` — deterministic, NaN-free. Without reference kinematics (a folder
    participant's idealized sweep, reward 0) cost, error_p75, rmse and cost_terms are None
    (`task.REFERENCE_KEYS`): the keys are those of every participant.
    """

    metadata = {"render_modes": []}

    def __init__(
        self, participant: str = "P1", motion: str = "calibrate", load_direction: str = DEFAULT_LOADS, instance: int = 0
    ):
        self.participant, self.motion, self.instance = participant, motion, instance
        self.task = task(participant, motion, load_direction, instance)
        self.action_space, self.observation_space = _spaces()

    def reset(self, *, seed: int | None = None, options: dict | None = None) -> tuple[np.ndarray, dict]:
        super().reset(seed=seed)
        return OBSERVATION.copy(), {}

    def step(self, action: ArrayLike) -> tuple[np.ndarray, float, bool, bool, dict]:
        evaluation = self.task.evaluate_action(action)
        return OBSERVATION.copy(), float(evaluation.reward), True, False, evaluation.info


class WristVectorEnv(VectorEnv):
    """`num_envs` designs per `step`, simulated in one batched call (same numbers as `WristEnv`)."""

    metadata = {"autoreset_mode": AutoresetMode.SAME_STEP, "render_modes": []}

    def __init__(
        self,
        num_envs: int = 1,
        participant: str = "P1",
        motion: str = "calibrate",
        load_direction: str = DEFAULT_LOADS,
        instance: int = 0,
        **_,
    ):
        self.num_envs = check_int("num_envs", num_envs, 1, MAX_BATCH)
        self.participant, self.motion, self.instance = participant, motion, instance
        self.task = task(participant, motion, load_direction, instance)
        self.single_action_space, self.single_observation_space = _spaces()
        self.action_space = gym.vector.utils.batch_space(self.single_action_space, self.num_envs)
        self.observation_space = gym.vector.utils.batch_space(self.single_observation_space, self.num_envs)

    def _observations(self):
        return np.tile(OBSERVATION, (self.num_envs, 1))

    def reset(self, *, seed: int | None = None, options: dict | None = None) -> tuple[np.ndarray, dict]:
        super().reset(seed=seed)
        return self._observations(), {}

    def step(self, actions: ArrayLike) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, dict]:
        actions = np.asarray(actions)
        if actions.shape != (self.num_envs, design.N_DESIGN):
            raise ValueError(f"actions must have shape ({self.num_envs}, {design.N_DESIGN}), but got {actions.shape}")
        evaluations = self.task.evaluate_actions(actions)
        infos = {}
        for i, e in enumerate(evaluations):
            infos = self._add_info(infos, e.info, i)
        rewards = evaluations.reward
        done = np.ones(self.num_envs, dtype=bool)
        return self._observations(), rewards, done, np.zeros(self.num_envs, dtype=bool), infos
