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
    """One participant's wrist model and one motion as a Gymnasium environment: calibrate its ligaments.

    Description
    -----------
    A participant-specific model of the wrist (radius and ulna, the carpal bodies, eleven Table 2
    ligaments and cartilage contact; Andreassen et al., preprint) is driven through one motion: the
    participant's unresisted trial ("calibrate"), its held-out resisted trial ("validate") or an idealized
    flexion–extension sweep ("idealized"). The agent proposes the ligaments' properties; the Numba explicit
    solver simulates the motion with them; the reward scores how closely the simulated scaphoid and lunate
    follow the participant's measured kinematics. Calibration is the search for the action of highest
    reward: the environment is a black-box objective in Gymnasium's interface, so an agent or an optimizer
    that speaks it can calibrate (`wrist_env.bench.calibrate` drives the same `wrist_env.task.Task`
    through the calibrators). `WristVectorEnv` simulates a population of designs in one batched call.

    Action Space
    ------------
    ``Box(-1, 1, (27,), float32)``: the 27 design variables normalized (`design.NAMES` order,
    `design.from_action` maps them to physical units):

    - 0–10: each Table 2 ligament's stiffness, mean + 3 SD · a (N/mm; `ligaments.LIGAMENT_NAMES` order);
    - 11–21: each ligament's reference strain l_ref / l0, 1.0 + 0.3 · a (dimensionless);
    - 22–26: the injury scalars of SLIL_v, SLIL_p, SLIL_d, RSC and LRL: below 0 a complete tear, +1 intact.

    Observation Space
    -----------------
    ``Box(-1, 1, (27,), float32)``, always zeros: the population-mean design in normalized units. Every
    episode asks the same question of the same model, so there is no state to observe; the observation is
    a fixed context and what a step did is in its ``info``.

    Rewards
    -------
    reward = −cost, the kinematic cost of the scaphoid and lunate against the motion's reference
    (`wrist_env.cost`): over the 2 bones × 6 DOF, the 75th percentile over frames of each DOF's error,
    normalized by the DOF's range in the reference, summed. 0 is a perfect fit; a failed simulation costs
    `cost.FAILED_COST`. Without reference kinematics (a folder participant's idealized sweep) the reward
    is 0.

    Starting State
    --------------
    Every episode starts from the model at rest in its neutral pose; nothing is random. ``reset(seed=...)``
    seeds the environment's ``np_random``, which nothing in it draws from; ``env.action_space.seed(seed)``
    seeds ``action_space.sample()``.

    Episode End
    -----------
    An episode is one step: the step that simulates the action returns ``terminated=True``. It is never
    truncated.

    Arguments
    ---------
    participant : str, default "P1"
        A registered participant: a built-in (P1, P2, P3) or a folder's (`wrist_env.register_participant`).
    motion : {"calibrate", "validate", "idealized"}, default "calibrate"
        The motion simulated (`motions.MOTIONS`).
    load_direction : str, default `settings.DEFAULT_LOADS`
        The loads' lines of action, one of `settings.LOAD_DIRECTIONS`; the default, "erhart2020", is the
        tendons' lines under the tensions of Erhart et al. 2020's rig.
    instance : int, default 0
        The problem instance of a built-in participant (`participants.instances`): 0 its shipped truth and
        trials, k ≥ 1 a truth drawn from the prior and the trials made from it.

    Info
    ----
    ``step``'s info, deterministic and NaN-free (`task.outputs`): ``cost``; per bone and DOF the
    75th-percentile absolute error ``error_p75`` and ``rmse`` (mm, deg) and the cost's terms
    ``cost_terms``; ``failed`` and the solver's ``status``; per frame the bones' ``poses``
    (n_frames, n_bodies, 4, 4) in mm, ``contact`` per pair (mean and peak pressure MPa, area mm², force N),
    ``bundle_force_n`` per ligament (N), the energies (N·mm), ``steps`` and ``settled``. Without
    reference kinematics ``cost``, ``error_p75``, ``rmse`` and ``cost_terms`` are None
    (`task.REFERENCE_KEYS`): the keys are the same for every participant.

    Examples
    --------
    >>> import gymnasium as gym
    >>> import wrist_env  # registers the ids wrist_env/<Motion>-<participant>-v0
    >>> env = gym.make("wrist_env/Calibrate-P1-v0")  # instance=k for a drawn problem
    >>> obs, info = env.reset(seed=0)
    >>> obs, reward, terminated, truncated, info = env.step(env.action_space.sample())
    >>> terminated, truncated, reward == -info["cost"]
    (True, False, True)

    Version History
    ---------------
    - v0: the only version so far. The model under it has changed without a new id (issues 33 and 54:
      the distal row, the tendons' loads, the TFCC); the docs' development notes date each change.
    """

    metadata = {"render_modes": []}

    def __init__(
        self, participant: str = "P1", motion: str = "calibrate", load_direction: str = DEFAULT_LOADS, instance: int = 0
    ):
        self.participant, self.motion, self.instance = participant, motion, instance
        self.task = task(participant, motion, load_direction, instance)
        self.action_space, self.observation_space = _spaces()

    def reset(self, *, seed: int | None = None, options: dict | None = None) -> tuple[np.ndarray, dict]:
        """Start an episode: the fixed observation, nothing simulated.

        Parameters
        ----------
        seed : int, optional
            Seeds ``self.np_random`` (Gymnasium's convention; nothing here draws from it).
        options : dict, optional
            Not used.

        Returns
        -------
        observation : ndarray of shape (27,), float32
            Zeros: the population-mean design in normalized units.
        info : dict
            Empty.
        """
        super().reset(seed=seed)
        return OBSERVATION.copy(), {}

    def step(self, action: ArrayLike) -> tuple[np.ndarray, float, bool, bool, dict]:
        """Simulate one design through the motion and score it: the whole episode.

        Parameters
        ----------
        action : array_like of shape (27,)
            The design variables normalized to [-1, 1] (see Action Space).

        Returns
        -------
        observation : ndarray of shape (27,), float32
            Zeros, as `reset` returns.
        reward : float
            −cost (see Rewards).
        terminated : bool
            Always True: an episode is one step.
        truncated : bool
            Always False.
        info : dict
            The simulation's outputs and the cost's terms (see Info).

        Raises
        ------
        DesignError
            An action of another shape, or not finite and in [-1, 1] (the message names the values).
        """
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
