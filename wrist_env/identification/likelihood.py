"""The posterior of the 22 materials given a trial: the one owner of the likelihood and the prior.

Prior: the population (preprint Table 2) as independent standard normals in z units (Table 2 SD
from the mean), truncated to the action box (|z| ≤ 3, `design.SPAN_SD`).

Residuals: the six-DOF errors (`frames.error_dof`, mm and deg, at the centroid) of the scaphoid
and the lunate at every frame of a trial, each over the 4DCT tracking noise of its DOF, `NOISE`
(0.2 mm, 0.5°). The synthetic trials carry 0.2 mm and 0.5° RMS rigid noise (0.12 mm, 0.29° per
axis); at the hidden truth the default model's residuals measure 0.12–0.19 mm and 0.5–0.8° RMS per
DOF (P2's grip trial 0.2–0.4 mm, 1.1–2.7°: the model is driven by the trial's capitate poses, whose
tracking noise moves the proximal row; `experiments/research/model_error.py`). So `NOISE` is the per-DOF noise
the model can be expected to reach; a design that fits much closer fits noise and model error.

MAP objective (what `+prior` calibrators minimize): the negative log posterior under Gaussian
noise of SD `NOISE`, up to a constant,

    map_objective(z) = ½ Σ residual² + ½ Σ z²

so the prior's weight relative to the kinematic misfit is set by the noise level alone. A failed
simulation is worth `FAILED_OBJECTIVE`.

Log likelihood of the Bayesian calibrator (`log_likelihood`): the same residuals with the noise
scale of the translations and of the rotations unknown, each integrated out under Jeffreys' prior
(p(σ) ∝ 1/σ): −(n/2)·log(Σ r²) per group of n residuals. It learns how far the model can follow
the trial (noise plus model error) instead of assuming the 4DCT noise is all of it.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from wrist_env.cost import COST_BONES
from wrist_env.design import SPAN_SD
from wrist_env.frames import error_dof
from wrist_env.model import BONES

if TYPE_CHECKING:
    from wrist_env.task import Evaluation, Task

NOISE = np.array([0.2, 0.2, 0.2, 0.5, 0.5, 0.5])
"""4DCT tracking noise per DOF (mm, mm, mm, deg, deg, deg): the residuals' unit."""
FAILED_OBJECTIVE = 1e6
"""MAP objective of a failed simulation: far above any run that tracks (O(10²–10⁴))."""
BOUND_Z = SPAN_SD
"""The prior's truncation, |z| ≤ 3 (the action box)."""


def residuals(task: Task, poses: np.ndarray, reference: np.ndarray | None = None) -> np.ndarray:
    """Per-frame DOF errors of the cost bones over `NOISE`, shape (2, n_frames, 6).

    poses: a simulation's poses (n_frames, n_bodies, 4, 4); reference: (2, n_frames, 4, 4) in
    `COST_BONES` order (default: the task's trial).
    """

    reference = task.reference if reference is None else reference
    out = []
    for b, bone in enumerate(COST_BONES):
        i = BONES.index(bone)
        out.append(error_dof(poses[:, i], reference[b], task.model.centroid[i]) / NOISE)
    return np.stack(out)


def in_box(z: ArrayLike) -> np.ndarray:
    """Whether z (..., 22) lies in the prior's box |z| ≤ 3, shape (...)."""
    return np.all(np.abs(np.asarray(z, dtype=np.float64)) <= BOUND_Z, axis=-1)


def log_prior(z: ArrayLike) -> np.ndarray:
    """Log density (..., ) of z (..., 22) under the population prior, up to a constant; −inf outside |z| ≤ 3."""
    z = np.asarray(z, dtype=np.float64)
    return np.where(in_box(z), -0.5 * np.sum(z**2, axis=-1), -np.inf)


def map_objective(task: Task, evaluation: Evaluation, z: ArrayLike) -> float:
    """½ Σ residual² + ½ Σ z² of one evaluated design with materials z (22,); `FAILED_OBJECTIVE` if failed."""
    if evaluation.failed:
        return FAILED_OBJECTIVE
    r = residuals(task, evaluation.result.poses)
    value = 0.5 * float(np.sum(r**2)) + 0.5 * float(np.sum(np.asarray(z, dtype=np.float64) ** 2))
    return value if np.isfinite(value) else FAILED_OBJECTIVE


def log_likelihood(r: np.ndarray) -> float:
    """Log likelihood of residuals r (2, n_frames, 6) with the translation and rotation noise scales
    integrated out (Jeffreys), up to a constant; −inf if not finite."""
    r = np.asarray(r, dtype=np.float64)
    total = 0.0
    for group in (r[..., :3], r[..., 3:]):
        total -= 0.5 * group.size * np.log(np.sum(group**2))
    return float(total) if np.isfinite(total) else -np.inf


def noise_scale(r: np.ndarray) -> np.ndarray:
    """RMS of the residuals' translations and rotations, in mm and deg (2,): the noise the fit implies."""
    r = np.asarray(r, dtype=np.float64) * NOISE
    return np.array([np.sqrt(np.mean(r[..., :3] ** 2)), np.sqrt(np.mean(r[..., 3:] ** 2))])
