"""The reference designs a leaderboard compares against: the population and the hidden truth, scored."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from wrist_env import design
from wrist_env.cost import COST_BONES
from wrist_env.frames import DOF_NAMES
from wrist_env.motions import TRIAL_MOTIONS
from wrist_env.task import task


@dataclass
class Reference:
    """A problem's population (and, if built in, hidden-truth) design scored on both trials.

    A problem is a participant's instance (0: the shipped truth and trials).

    Parameters
    ----------
    participant : str
        The participant's name.
    population : dict
        ``{"calibrate": score, "validate": score}`` of the population design; score = ``{"cost", "failed",
        "rmse"}`` (rmse: ``{bone: {DOF: mm or deg}}``).
    truth : dict or None
        The same for the hidden truth; None for a participant without one.
    instance : int, default 0
        The problem instance.
    """

    participant: str
    population: dict  # {"calibrate": score, "validate": score}; score = {"cost", "failed", "rmse"}
    truth: dict | None
    instance: int = 0


def _score(evaluation) -> dict:
    return {"cost": float(evaluation.cost), "failed": bool(evaluation.failed), "rmse": evaluation.info.get("rmse")}


def reference(participant: str, instance: int = 0) -> Reference:
    """Simulate the population design (and the instance's hidden truth) on the calibration and held-out trials.

    Parameters
    ----------
    participant : str
        A registered participant's name.
    instance : int, default 0
        The problem instance (`participants.instances`; 0: the shipped truth and trials).

    Returns
    -------
    Reference
        The designs' scores (cost, failed, RMSE in mm and deg) on both of the instance's trials.

    Raises
    ------
    ParticipantError
        An unknown participant, or an instance k ≥ 1 of a folder participant.
    """

    tasks = {m: task(participant, m, instance=instance) for m in TRIAL_MOTIONS}
    designs = {"population": design.population()}
    if tasks["calibrate"].truth is not None:
        designs["truth"] = tasks["calibrate"].truth
    scores = {name: {m: _score(t.evaluate(d)) for m, t in tasks.items()} for name, d in designs.items()}
    return Reference(participant, scores["population"], scores.get("truth"), instance)


def rmse_array(rmse: dict | None) -> np.ndarray:
    """{bone: {DOF: value}} → (2, 6) in COST_BONES × DOF_NAMES order (NaN when missing)."""
    out = np.full((len(COST_BONES), len(DOF_NAMES)), np.nan)
    for b, bone in enumerate(COST_BONES):
        for d, dof in enumerate(DOF_NAMES):
            v = ((rmse or {}).get(bone) or {}).get(dof)
            out[b, d] = np.nan if v is None else v
    return out
