"""Gymnasium ids for every participant: `wrist_env/Calibrate-P1-v0`, `wrist_env/Validate-P1-v0`,
`wrist_env/Idealized-P1-v0`, … (registered when `wrist_env` is imported)."""

from __future__ import annotations

from collections.abc import Iterable
from typing import TYPE_CHECKING

import gymnasium as gym

from wrist_env.participants import builtin, registry
from wrist_env.trial import MOTIONS

if TYPE_CHECKING:
    from pathlib import Path

NAMESPACE = "wrist_env"
MOTION_PREFIX = {m: m.capitalize() for m in MOTIONS}


def env_id(participant: str, motion: str) -> str:
    """The Gymnasium id of a participant's motion (`trial.MOTIONS`)."""
    return f"{NAMESPACE}/{MOTION_PREFIX[motion]}-{participant}-v0"


def register_ids(participant: str, motions: Iterable[str] = tuple(MOTION_PREFIX)) -> tuple[str, ...]:
    """Register (once) and return the ids of a known participant's motions."""
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


def register_participant(folder: str | Path) -> tuple[str, ...]:
    """Validate a participant folder (see the README's folder format) and register its ids.

    Returns the new ids: Calibrate and Idealized always, Validate when the folder
    has a trial with role "validate".
    """
    name = registry.add_folder(folder)
    roles = {t.role for t in registry.trials(name).values()}
    motions = [m for m in MOTION_PREFIX if m != "validate" or "validate" in roles]
    return register_ids(name, motions)


def registered_ids() -> tuple[str, ...]:
    """All wrist-env ids in the Gymnasium registry."""
    return tuple(i for i in gym.registry if i.startswith(NAMESPACE + "/"))


for _name in builtin.BUILTIN:
    register_ids(_name)
