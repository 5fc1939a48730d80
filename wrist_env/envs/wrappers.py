"""Action wrappers over the 27 design variables."""

from __future__ import annotations

import gymnasium as gym
import numpy as np

from wrist_env import design


class FreezeVariables(gym.ActionWrapper):
    """Hold some design variables at fixed normalized values; the agent sets the rest.

    frozen: {variable name (`design.NAMES`) or index: normalized value in [-1, 1]}.
    The default freezes the five injury scalars at +1 (ligaments intact), as
    calibration does.
    """

    def __init__(self, env: gym.Env, frozen: dict | None = None):
        super().__init__(env)
        frozen = design.INTACT_INJURY if frozen is None else frozen
        index = {(design.NAMES.index(k) if isinstance(k, str) else int(k)): float(v) for k, v in frozen.items()}
        self.frozen_index = np.array(sorted(index), dtype=np.int64)
        self.frozen_value = np.array([index[i] for i in self.frozen_index])
        self.free_index = np.setdiff1d(np.arange(design.N_DESIGN), self.frozen_index)
        self.action_space = gym.spaces.Box(-1.0, 1.0, (len(self.free_index),), dtype=np.float32)

    def action(self, action):
        full = np.empty(design.N_DESIGN, dtype=np.float32)
        full[self.free_index] = action
        full[self.frozen_index] = self.frozen_value
        return full
