"""Gymnasium ids for every participant: `wrist_env/Calibrate-P1-v0`, `wrist_env/Validate-P1-v0`,
`wrist_env/Idealized-P1-v0`, … (the built-in ones registered when `wrist_env` and `gymnasium` are
both imported; `envs.ids`)."""

from __future__ import annotations

from collections.abc import Iterable
from typing import TYPE_CHECKING

import gymnasium as gym

from wrist_env.envs import ids
from wrist_env.envs.ids import MOTION_PREFIX, NAMESPACE, env_id
from wrist_env.motions import MOTIONS

if TYPE_CHECKING:
    from pathlib import Path

__all__ = ["MOTION_PREFIX", "NAMESPACE", "env_id", "register_ids", "register_participant", "registered_ids"]


def register_ids(participant: str, motions: Iterable[str] = MOTIONS) -> tuple[str, ...]:
    """Register (once) and return the ids of a known participant's motions.

    Parameters
    ----------
    participant : str
        A known participant's name (built-in or registered from a folder).
    motions : iterable of str, default `motions.MOTIONS`
        The motions to register ids for.

    Returns
    -------
    tuple of str, shape (n_motions,)
        The ids, ``wrist_env/<Motion>-<participant>-v0``, in the order of `motions`.

    Examples
    --------
    >>> from wrist_env.envs import register_ids
    >>> register_ids("P1", ["calibrate"])
    ('wrist_env/Calibrate-P1-v0',)
    """
    return ids.register_ids(gym, participant, motions)


def register_participant(folder: str | Path) -> tuple[str, ...]:
    """Validate a participant folder and register its Gymnasium ids.

    The folder's format is described in docs/participants.md, "Registering your own participant".

    Parameters
    ----------
    folder : str or Path
        The participant folder (participant.toml, bone meshes, trial CSVs).

    Returns
    -------
    tuple of str
        The new ids: Calibrate and Idealized always, Validate when the folder has a trial with role
        "validate".

    Raises
    ------
    ParticipantError
        The folder does not hold a valid participant (the message names the file and the rule), or its
        name is taken by a built-in participant or by another folder.
    """
    from wrist_env.participants import registry  # the model builder: heavy, needed only here

    name = registry.add_folder(folder)
    roles = {t.role for t in registry.trials(name).values()}
    motions = [m for m in MOTIONS if m != "validate" or "validate" in roles]
    return register_ids(name, motions)


def registered_ids() -> tuple[str, ...]:
    """All wrist-env ids in the Gymnasium registry.

    Returns
    -------
    tuple of str
        The ids in the ``wrist_env`` namespace, in the registry's order.
    """
    return tuple(i for i in gym.registry if i.startswith(NAMESPACE + "/"))
