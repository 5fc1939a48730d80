"""Action wrappers over the 27 design variables."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
from numpy.typing import ArrayLike

from wrist_env.design import full_action, split_variables


class FreezeVariables(gym.ActionWrapper):
    """Hold some design variables at fixed normalized values; the agent sets the rest.

    frozen: {variable name (`design.NAMES`) or index: normalized value in [-1, 1]}.
    The default freezes the five injury scalars at +1 (ligaments intact), as
    calibration does.
    """

    def __init__(self, env: gym.Env, frozen: dict | None = None):
        super().__init__(env)
        self.frozen = frozen
        self.free_index, self.frozen_index, self.frozen_value = split_variables(frozen)
        self.action_space = gym.spaces.Box(-1.0, 1.0, (len(self.free_index),), dtype=np.float32)

    def action(self, action: ArrayLike) -> np.ndarray:
        return full_action(action, self.frozen, dtype=np.float32)
