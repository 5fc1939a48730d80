"""How good a calibration is: its scores on a trial, its parameter recovery, the log's per-DOF errors.

The calibrated design of a benchmark cell is scored on the calibration trial and on the held-out
resisted trial ("validate"), and, where the problem instance has a hidden truth (built-in
participants), by parameter recovery: the RMS distance of its materials' z-scores to the truth's, in
Table 2 SD units (`CalibrationRun` and its summary keep them).
"""

from __future__ import annotations

import numpy as np

from wrist_env import design as design_vars
from wrist_env import table2
from wrist_env.cost import COST_BONES
from wrist_env.design import Design
from wrist_env.frames import DOF_NAMES
from wrist_env.task import Task


def rmse_vector(info: dict) -> np.ndarray:
    """The 12 per-DOF RMSE of an evaluation's info, in `RMSE_COLUMNS` order (NaN when missing)."""
    rmse = info.get("rmse") or {}
    return np.array(
        [np.nan if rmse.get(b, {}).get(d) is None else rmse[b][d] for b in COST_BONES for d in DOF_NAMES],
        dtype=np.float64,
    )


def recovery_error(calibrated: Design, truth: Design) -> float:
    """Parameter-recovery error: RMS over the 22 materials of z(calibrated) − z(truth), Table 2 SD units."""
    dz = table2.z_scores(calibrated) - table2.z_scores(truth)
    return float(np.sqrt(np.mean(dz**2)))


def unsettled_frames(evaluation) -> int | None:
    """Frames of an evaluated run whose hold ran out before equilibrium; None if the run failed."""
    return None if evaluation.failed else int(np.sum(~np.asarray(evaluation.info["settled"], dtype=bool)))


def _score(evaluation) -> dict:
    """{"cost", "failed", "rmse", "error_p75", "unsettled_frames"} of one evaluation of a design."""
    info = evaluation.info
    return {
        "cost": float(evaluation.cost),
        "failed": bool(evaluation.failed),
        "rmse": info.get("rmse"),
        "error_p75": info.get("error_p75"),
        "unsettled_frames": unsettled_frames(evaluation),
    }


def score(result, calibration: Task, validation: Task) -> dict:
    """The `CalibrationRun` fields that judge a calibrator's result: its best evaluation, the calibrated
    design, its scores on the calibration trial and the held-out one (`validation`), and its parameter
    recovery and the population design's against the instance's hidden truth (None without one)."""
    calibrated = design_vars.from_action(design_vars.full_action(result.x))
    at_calibrate = _score(calibration.evaluate(calibrated))
    at_validate = _score(validation.evaluate(calibrated))
    recovery = recovery_population = None
    if calibration.truth is not None:  # the instance's hidden truth
        recovery = recovery_error(calibrated, calibration.truth)
        recovery_population = recovery_error(design_vars.population(), calibration.truth)
    return {
        "design": calibrated,
        "calibrate": at_calibrate,
        "validate": at_validate,
        "recovery_z": recovery,
        "recovery_z_population": recovery_population,
        "best_eval": int(np.argmin(result.history_fun)),
    }
