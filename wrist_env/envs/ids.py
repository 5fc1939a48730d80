"""The Gymnasium ids of wrist-env's tasks, `wrist_env/<Motion>-<participant>-v0`, registered with string
entry points: registering imports neither the environments nor the builder (only Gymnasium's registry)."""

from __future__ import annotations

from collections.abc import Iterable
from types import ModuleType

from wrist_env.motions import MOTIONS

NAMESPACE = "wrist_env"
MOTION_PREFIX = {m: m.capitalize() for m in MOTIONS}


def env_id(participant: str, motion: str) -> str:
    """The Gymnasium id of a participant's motion.

    Parameters
    ----------
    participant : str
        The participant's name.
    motion : str
        One of `motions.MOTIONS`.

    Returns
    -------
    str
        ``wrist_env/<Motion>-<participant>-v0``.

    Raises
    ------
    KeyError
        `motion` is not one of `motions.MOTIONS`.

    Examples
    --------
    >>> env_id("P1", "calibrate")
    'wrist_env/Calibrate-P1-v0'
    """
    return f"{NAMESPACE}/{MOTION_PREFIX[motion]}-{participant}-v0"


def register_ids(gym: ModuleType, participant: str, motions: Iterable[str] = MOTIONS) -> tuple[str, ...]:
    """Register (once) in `gym` (the gymnasium module) and return the ids of a participant's motions."""
    ids = []
    for motion in motions:
        i = env_id(participant, motion)
        if i not in gym.registry:
            gym.register(
                i,
                entry_point="wrist_env.envs.wrist:WristEnv",
                vector_entry_point="wrist_env.envs.wrist:WristVectorEnv",
                kwargs={"participant": participant, "motion": motion},
            )
        ids.append(i)
    return tuple(ids)
