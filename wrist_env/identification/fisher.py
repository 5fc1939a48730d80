"""What a trial can identify: the Gauss–Newton (Fisher) matrix of the per-frame kinematic residuals
at the hidden truth, in z units (Table 2 SD).

The residuals of a design are `posterior.residuals`: the six-DOF errors of the scaphoid and lunate
at every frame over the 4DCT tracking noise of each DOF (`posterior.NOISE`, 0.2 mm, 0.5°). Their
Jacobian J with respect to the 22 materials is taken by central differences at the truth (step 0.25 SD), simulated with a 10× tighter equilibrium
tolerance than the default (`SETTINGS`; at the default the solver's residual moves make the
differences step-dependent: 20 % between 0.25 and 0.125 SD on P1, 15 % with it). F = JᵀJ is the
Fisher information of z under that Gaussian noise: an eigenvector with eigenvalue λ is a
combination of materials the trial pins down to 1/√λ SD (≥ 1 SD: no better than the population
prior). Trials add: F of the calibration and the held-out trial together is the sum of theirs.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from wrist_env import design, table2
from wrist_env.identification.likelihood import residuals
from wrist_env.motions import TRIAL_MOTIONS
from wrist_env.participants import builtin
from wrist_env.solver.settings import SolverSettings
from wrist_env.solver.simulate import simulate_batch
from wrist_env.task import Task, cost_poses

STEP_Z = 0.25  # central-difference step, SD units
SETTINGS = SolverSettings(tolerance=1e-4, force_floor_n=1e-3, max_hold_steps=6400).diagonal()
"""Tight equilibria for central differences, on the diagonal mass the committed identifiability study was
run with (issue 52 made the block mass the default; this study waits for the load-path issue's regeneration)."""
TRIALS = TRIAL_MOTIONS


@dataclass(frozen=True)
class Spectrum:
    """Eigen-decomposition of a Fisher matrix (22, 22) in z units, largest eigenvalue first.

    eigenvalues (22,): information (1/SD²); eigenvectors (22, 22): column k is direction k;
    sd (22,): 1/√eigenvalue, the SD to which the trial pins direction k (inf where λ = 0).
    """

    eigenvalues: np.ndarray
    eigenvectors: np.ndarray

    @property
    def sd(self) -> np.ndarray:
        with np.errstate(divide="ignore"):
            return 1.0 / np.sqrt(np.maximum(self.eigenvalues, 0.0))

    def identified(self, threshold_sd: float = 1.0) -> int:
        """Directions pinned tighter than `threshold_sd` (by default: tighter than the prior)."""
        return int(np.sum(self.sd < threshold_sd))


def spectrum(fisher: np.ndarray) -> Spectrum:
    """`Spectrum` of a symmetric Fisher matrix."""
    values, vectors = np.linalg.eigh(0.5 * (fisher + fisher.T))
    order = np.argsort(values)[::-1]
    return Spectrum(values[order], vectors[:, order])


def jacobian(task: Task, center: design.Design, step: float = STEP_Z) -> np.ndarray:
    """∂(residuals)/∂z at `center`, shape (2 · n_frames · 6, 22), by central differences of `step` SD."""

    z0 = table2.z_scores(center)
    designs = [center]
    for i in range(design.N_MATERIAL):
        for sign in (1.0, -1.0):
            z = z0.copy()
            z[i] += sign * step
            designs.append(table2.with_z(center, z))
    runs = simulate_batch(task.model, designs, task.driver, prepared=task.prepared)
    failed = [k for k, r in enumerate(runs) if not r.ok]
    if failed:
        raise RuntimeError(f"{task.participant} {task.motion}: {len(failed)} perturbed runs failed (step {step} SD)")
    reference = cost_poses(runs[0].poses)
    r = np.stack([residuals(task, run.poses, reference).ravel() for run in runs[1:]])
    return ((r[0::2] - r[1::2]) / (2.0 * step)).T


def fisher(participant: str, motion: str, center: design.Design | None = None, step: float = STEP_Z) -> np.ndarray:
    """JᵀJ (22, 22) of a trial at `center` (default: the participant's hidden truth)."""
    center = builtin.truth(participant) if center is None else center
    J = jacobian(Task(participant, motion, settings=SETTINGS), center, step)
    return J.T @ J


def posterior_sd(fisher: np.ndarray) -> np.ndarray:
    """Per-material SD (22,) in z units of the Laplace posterior with the population prior N(0, 1)
    (Table 2): sqrt(diag((F + I)⁻¹)); 1 where the trial tells nothing, → 0 where it pins a material."""
    return np.sqrt(np.diag(np.linalg.inv(fisher + np.eye(len(fisher)))))


def study(participants, out=None):
    """Per participant, the Fisher matrices of the calibration and held-out trials at the truth:
    (materials table: participant, trials, material, posterior_sd; spectrum table: participant,
    trials, direction, eigenvalue, sd, leading materials); written as CSV when `out` is given (the
    command draws them: `wrist_env.figures.identifiability.plot`, a figure per participant)."""
    import pandas as pd

    materials, spectra = [], []
    for participant in participants:
        F = {motion: fisher(participant, motion) for motion in TRIALS}
        for trials, f in (("calibrate", F["calibrate"]), ("validate", F["validate"]), ("both", sum(F.values()))):
            for name, sd in zip(design.NAMES[: design.N_MATERIAL], posterior_sd(f)):
                materials.append({"participant": participant, "trials": trials, "material": name, "posterior_sd": sd})
            s = spectrum(f)
            for k in range(len(f)):
                v = s.eigenvectors[:, k]
                lead = np.argsort(-np.abs(v))[:3]
                spectra.append(
                    {
                        "participant": participant,
                        "trials": trials,
                        "direction": k,
                        "eigenvalue": s.eigenvalues[k],
                        "sd": s.sd[k],
                        "leading_materials": " ".join(f"{v[j]:+.2f}·{design.NAMES[j]}" for j in lead),
                    }
                )
    tables = pd.DataFrame(materials), pd.DataFrame(spectra)
    if out is not None:
        from pathlib import Path

        out = Path(out)
        out.mkdir(parents=True, exist_ok=True)
        tables[0].to_csv(out / "identifiability_materials.csv", index=False)
        tables[1].to_csv(out / "identifiability_spectrum.csv", index=False)
    return tables
