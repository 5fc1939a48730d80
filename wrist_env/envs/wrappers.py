"""Action wrappers over the 27 design variables."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
from numpy.typing import ArrayLike, DTypeLike

from wrist_env import design


def split_variables(frozen: dict | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(free indices, frozen indices, frozen values) of the 27 design variables.

    frozen: {variable name (`design.NAMES`) or index: normalized value in [-1, 1]}; default the
    five injury scalars at +1 (ligaments intact), as calibration does.
    """
    frozen = design.INTACT_INJURY if frozen is None else frozen
    index = {(design.NAMES.index(k) if isinstance(k, str) else int(k)): float(v) for k, v in frozen.items()}
    frozen_index = np.array(sorted(index), dtype=np.int64)
    free_index = np.setdiff1d(np.arange(design.N_DESIGN), frozen_index)
    return free_index, frozen_index, np.array([index[i] for i in frozen_index])


def full_action(free: ArrayLike, frozen: dict | None = None, dtype: DTypeLike = np.float64) -> np.ndarray:
    """The 27-variable action(s), shape (..., 27), of the free variables' values (..., n_free) with
    the `frozen` ones (see `split_variables`) filled in."""
    free_index, frozen_index, frozen_value = split_variables(frozen)
    free = np.asarray(free)
    full = np.empty(free.shape[:-1] + (design.N_DESIGN,), dtype=dtype)
    full[..., free_index] = free
    full[..., frozen_index] = frozen_value
    return full


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
