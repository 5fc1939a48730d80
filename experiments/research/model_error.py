"""Where the built-in trials' model error comes from: the fidelity gap or the capitate's tracking noise.

The built-in trials (`experiments/authoring/make_trials.py`) are a higher-fidelity run of the hidden truth
(finer contact, half the time step, tighter tolerance) with the capitate's rotations prescribed and
its translations free under load, and then 4DCT-like tracking noise on every bone. The calibration
model is driven by the trial's capitate poses, noise included. So the residuals of the scaphoid and
the lunate at the truth have three sources, which this script separates for P1–P3 by re-running the
trial's making without the noise:

- gap: the default model driven by the noise-free high-fidelity capitate, against the noise-free
  scaphoid and lunate: the fidelity gap alone;
- + capitate noise: the same with the capitate's tracking noise (`builtin.tracking_noise`, `DRAWS`
  draws; translation or rotation only as well): the noise the driver passes to the proximal row;
- trial: against the built-in trial itself (its own noise draws on all three bones).

Each at the hidden truth and at the MAP (`map_estimate`, its default 24 starts): sums of squared
residuals in 4DCT-noise units (`likelihood.residuals`, 180 of them; tracking noise alone gives ~60)
and, for the gap and the trial, their RMS in mm and deg. Writes `leaderboards/posterior/model_error.csv`.

Run: `python experiments/research/model_error.py [P1 P2 P3]` (~8 min; builds the high-fidelity models first).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pandas as pd

from wrist_env import design, table2
from wrist_env.frames import cardan_rotation
from wrist_env.identification import likelihood
from wrist_env.identification.map import map_estimate
from wrist_env.model import BONES
from wrist_env.participants import builtin
from wrist_env.participants.registry import load_model
from wrist_env.participants.synthetic import HIGH_FIDELITY_BUILD, HIGH_FIDELITY_SOLVER, capitate_motion
from wrist_env.solver.drivers import experimental, loaded
from wrist_env.solver.simulate import simulate
from wrist_env.task import cost_poses, task

DRAWS = 16
OUT = Path(__file__).resolve().parents[2] / "leaderboards" / "posterior" / "model_error.csv"
CAPITATE = BONES.index("capitate")


def capitate_noise(poses: np.ndarray, centroid: np.ndarray, rng, part: str) -> np.ndarray:
    """The capitate's poses with tracking noise: all of it, or its translation or rotation only."""
    noisy = builtin.tracking_noise(poses, centroid, rng)
    at = np.einsum("fij,j->fi", poses[:, :3, :3], centroid) + poses[:, :3, 3]
    if part == "translation":  # the centroid shifted, no turn
        shifted = np.einsum("fij,j->fi", noisy[:, :3, :3], centroid) + noisy[:, :3, 3]
        noisy = poses.copy()
        noisy[:, :3, 3] += shifted - at
    elif part == "rotation":  # turned about the centroid, which stays put
        noisy[:, :3, 3] = at - np.einsum("fij,j->fi", noisy[:, :3, :3], centroid)
    return noisy


def rows(name: str) -> list[dict]:
    calibration = task(name, "calibrate")
    fine = load_model(name, HIGH_FIDELITY_BUILD)
    angles, load = capitate_motion(builtin.info(name).task, "unresisted")
    run = simulate(fine, builtin.truth(name), loaded(fine, cardan_rotation(angles), load), HIGH_FIDELITY_SOLVER)
    capitate, clean = run.poses[:, CAPITATE], cost_poses(run.poses)
    map_z, *_ = map_estimate(calibration)
    out = []
    for label, z in (("truth", table2.z_scores(builtin.truth(name))), ("MAP", map_z)):
        d = table2.with_z(design.population(), z)

        def residuals(driven: np.ndarray) -> np.ndarray:
            return likelihood.residuals(
                calibration, simulate(calibration.model, d, experimental(calibration.model, driven)).poses, clean
            )

        gap = residuals(capitate)
        trial = likelihood.residuals(calibration, calibration.evaluate(d).result.poses)
        row = {"participant": name, "design": label, "gap_ss": float(np.sum(gap**2))}
        for part in ("all", "translation", "rotation"):
            rng = np.random.default_rng(7)
            ss = [
                float(np.sum(residuals(capitate_noise(capitate, fine.centroid[CAPITATE], rng, part)) ** 2))
                for _ in range(DRAWS)
            ]
            row[f"capitate_noise_{part}_ss_median"] = float(np.median(ss))
            if part == "all":
                row["capitate_noise_ss_min"], row["capitate_noise_ss_max"] = min(ss), max(ss)
        row["trial_ss"] = float(np.sum(trial**2))
        (row["gap_mm"], row["gap_deg"]), (row["trial_mm"], row["trial_deg"]) = (
            likelihood.noise_scale(gap),
            likelihood.noise_scale(trial),
        )
        out.append(row)
        print(
            f"{name} {label:5s}: gap {row['gap_ss']:5.0f} ({row['gap_mm']:.2f} mm, {row['gap_deg']:.2f} deg); "
            f"+ capitate noise {row['capitate_noise_all_ss_median']:5.0f} (range {row['capitate_noise_ss_min']:.0f}-{row['capitate_noise_ss_max']:.0f}; "
            f"translation only {row['capitate_noise_translation_ss_median']:.0f}, rotation only "
            f"{row['capitate_noise_rotation_ss_median']:.0f}); trial {row['trial_ss']:5.0f} "
            f"({row['trial_mm']:.2f} mm, {row['trial_deg']:.2f} deg)",
            flush=True,
        )
    return out


def main(names: list[str]) -> pd.DataFrame:
    table = pd.DataFrame([r for name in names for r in rows(name)])
    OUT.parent.mkdir(parents=True, exist_ok=True)
    table.to_csv(OUT, index=False)
    print(f"written to {OUT}")
    return table


if __name__ == "__main__":
    main(sys.argv[1:] or list(builtin.BUILTIN))
