"""Global sensitivity of the kinematic cost and the 12 scaphoid and lunate DOF errors to the 22
ligament materials: Morris screening and Sobol first and total indices (SALib), simulated through
the batched vector environment.

The materials vary uniformly over the action box [-1, 1] (Table 2 mean ± 3 SD); the five injury
scalars are held intact, as calibration does. The outputs of a design are its kinematic cost and
the 75th-percentile absolute error of each scaphoid and lunate DOF (mm, deg), as `wrist_env.cost`
computes them. A failed run (dislocated) gets, for every output, the largest value of the runs
that did not fail (failing is the worst outcome; the failure cost 1,000 would swamp the indices);
the share of failed runs is reported with the indices.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
from SALib.analyze import morris as morris_analyze
from SALib.analyze import sobol as sobol_analyze
from SALib.sample import morris as morris_sample
from SALib.sample import sobol as sobol_sample
from tqdm import tqdm

from wrist_env import design
from wrist_env.cost import COST_BONES, DOF_NAMES
from wrist_env.design import full_action
from wrist_env.errors import InputError
from wrist_env.limits import MAX_SEED, MAX_SENSITIVITY_N, MIN_SENSITIVITY_N, check_int
from wrist_env.motions import MOTIONS
from wrist_env.task import require_reference, task

METHODS = ("morris", "sobol")
MATERIALS = design.NAMES[: design.N_MATERIAL]
OUTPUTS = ("cost",) + tuple(f"{bone}.{dof}" for bone in COST_BONES for dof in DOF_NAMES)
"""The outputs: the cost, then the 75th-percentile error of each DOF of the scaphoid and lunate."""
BATCH = 64  # designs per vector-env step


def problem(names=MATERIALS, bounds=(-1.0, 1.0)) -> dict:
    """A SALib problem: `names` uniform on `bounds` (by default the 22 materials on the action box)."""
    return {"num_vars": len(names), "names": list(names), "bounds": [list(bounds)] * len(names)}


def check_size(method: str, n: int, seed: int) -> int:
    """`n` if `method` can take it: an integer in [`MIN_SENSITIVITY_N`, `MAX_SENSITIVITY_N`] (Morris
    trajectories), for Sobol also a power of 2; `seed` a non-negative 32-bit integer. `InputError` saying
    what n would do, before anything is sampled."""
    if method not in METHODS:
        raise InputError(f"method must be one of {METHODS}, but got {method!r}")
    check_int("seed", seed, 0, MAX_SEED)
    n = check_int("n", n, MIN_SENSITIVITY_N, MAX_SENSITIVITY_N, "Morris trajectories or Sobol base size")
    if method == "sobol" and n & (n - 1):
        below = 1 << (n.bit_length() - 1)
        raise InputError(
            f"sobol needs n a power of 2 (Sobol' sequences), at least {MIN_SENSITIVITY_N}, but got {n}: "
            f"the nearest are {below} and {2 * below}"
        )
    return n


def sample(method: str, spec: dict, n: int, seed: int) -> np.ndarray:
    """Sample points (m, num_vars): Morris with n trajectories (m = n (d + 1)), Sobol (Saltelli) with
    base size n, a power of 2 (m = n (d + 2), no second-order indices); n checked first (`check_size`)."""
    n = check_size(method, n, seed)
    if method == "morris":
        return morris_sample.sample(spec, n, num_levels=4, seed=seed)
    return sobol_sample.sample(spec, n, calc_second_order=False, seed=seed)


def indices(method: str, spec: dict, X: np.ndarray, Y: np.ndarray, seed: int = 0) -> pd.DataFrame:
    """One row per variable of `spec` and column of Y (m, k) (outputs numbered 0..k−1): Morris mu*
    (mean absolute elementary effect, output units per whole range of the variable), sigma and mu*'s
    confidence, or Sobol S1, ST and their confidences (95 %)."""
    rows = []
    for k in range(Y.shape[1]):
        y = np.ascontiguousarray(Y[:, k])
        if method == "morris":
            r = morris_analyze.analyze(spec, X, y, num_levels=4, seed=seed)
            cols = {"mu_star": r["mu_star"], "mu_star_conf": r["mu_star_conf"], "sigma": r["sigma"]}
        else:
            r = sobol_analyze.analyze(spec, y, calc_second_order=False, seed=seed)
            cols = {"S1": r["S1"], "S1_conf": r["S1_conf"], "ST": r["ST"], "ST_conf": r["ST_conf"]}
        for i, name in enumerate(spec["names"]):
            rows.append({"output": k, "material": name} | {c: float(np.asarray(v)[i]) for c, v in cols.items()})
    return pd.DataFrame(rows)


def evaluate(participant: str, motion: str, X: np.ndarray, batch: int = BATCH) -> tuple[np.ndarray, np.ndarray]:
    """Outputs (m, 13) (`OUTPUTS`) and failed (m,) of the material points X (m, 22), simulated by the
    participant's task `batch` designs per call (`Task.evaluate_batch`, as the environments); failed runs'
    outputs filled (module doc)."""
    motion_task = task(participant, motion)
    # the actions as the environments' float32 action space holds them (the committed indices were made so)
    actions = full_action(X).astype(np.float32)
    Y = np.zeros((len(X), len(OUTPUTS)))
    failed = np.zeros(len(X), bool)
    for start in tqdm(range(0, len(X), batch), desc=f"{participant} {motion}", unit="batch", leave=False):
        chunk = actions[start : start + batch]
        for i, e in enumerate(motion_task.evaluate_actions(chunk), start=start):
            Y[i, 0] = e.cost
            for j, name in enumerate(OUTPUTS[1:], start=1):
                bone, dof = name.split(".", 1)
                Y[i, j] = e.info["error_p75"][bone][dof]
            failed[i] = e.info["failed"]
    if failed.all():
        raise RuntimeError(f"{participant} {motion}: every one of the {len(X)} runs failed; no indices")
    Y[failed] = Y[~failed].max(axis=0)
    return Y, failed


def study(
    participant: str, method: str = "morris", n: int = 20, motions=MOTIONS, seed: int = 0, out: str | Path | None = None
) -> pd.DataFrame:
    """Indices of every output to every material for each motion: one row per (motion, output,
    material), with the motion's failed share; written to `out`/sensitivity_<participant>_<method>.csv
    when `out` is given (the command draws it beside, .png: `wrist_env.figures.sensitivity.plot`). The method, n and seed are checked before anything runs
    (`sample`'s `check_size`); ParticipantError, before anything is simulated, if a motion has no reference
    kinematics (a folder participant's idealized sweep): its outputs would be undefined."""
    for motion in motions:
        require_reference(participant, motion)
    spec = problem()
    X = sample(method, spec, n, seed)
    frames = []
    for motion in motions:
        Y, failed = evaluate(participant, motion, X)
        table = indices(method, spec, X, Y, seed)
        table["output"] = [OUTPUTS[k] for k in table["output"]]
        table.insert(0, "motion", motion)
        table.insert(0, "participant", participant)
        table["runs"] = len(X)
        table["failed_share"] = float(failed.mean())
        frames.append(table)
    result = pd.concat(frames, ignore_index=True)
    if out is not None:
        out = Path(out)
        out.mkdir(parents=True, exist_ok=True)
        stem = out / f"sensitivity_{participant}_{method}"
        result.to_csv(stem.with_suffix(".csv"), index=False)
    return result
