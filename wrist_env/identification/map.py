"""The maximum a posteriori design: trust-region Gauss–Newton on the residuals and the prior, and the
Laplace covariance around it (the Bayesian calibrator's start)."""

from __future__ import annotations

import numpy as np
from scipy.optimize import least_squares

from wrist_env import design, table2
from wrist_env.identification import likelihood
from wrist_env.identification.settings import MAP_STARTS
from wrist_env.task import Task

FD_STEP_Z = 0.1
"""Forward-difference step of the MAP search's Jacobian (SD units)."""
FAILED_RESIDUAL = 30.0
"""Residual (noise units) of every DOF of a failed run in the MAP search."""


def map_estimate(
    calibration: Task, starts: int = MAP_STARTS, seed: int = 0, max_evaluations: int = 40
) -> tuple[np.ndarray, np.ndarray, np.ndarray, int]:
    """(MAP z (22,), its residuals (n,), their Jacobian (n, 22), simulations run): the best of
    trust-region Gauss–Newton runs (SciPy's `least_squares`, TRF, |z| ≤ 3) on [residuals; z] from the
    population design and `starts` − 1 draws of N(0, 0.7²) (the misfit is multimodal: on P1, 1 of 6
    random starts reached the basin of the hidden truth; see `MAP_STARTS`)."""
    base, runs = design.population(), [0]
    n = 2 * calibration.reference.shape[1] * 6

    def stacked(Z):
        evaluations = calibration.evaluate_batch([table2.with_z(base, z) for z in Z])
        runs[0] += len(Z)
        out = []
        for z, e in zip(Z, evaluations):
            r = np.full(n, FAILED_RESIDUAL) if e.failed else likelihood.residuals(calibration, e.result.poses).ravel()
            out.append(np.concatenate([r, z]))
        return np.array(out)

    def jacobian(z):
        R = stacked(np.vstack([z, z + FD_STEP_Z * np.eye(len(z))]))
        return ((R[1:] - R[0]) / FD_STEP_Z).T

    rng = np.random.default_rng(seed)
    z0 = np.vstack([np.zeros(design.N_MATERIAL), rng.normal(0.0, 0.7, (starts - 1, design.N_MATERIAL))])
    bound = likelihood.BOUND_Z
    best = None
    for z in np.clip(z0, -0.95 * bound, 0.95 * bound):
        solution = least_squares(
            lambda z: stacked(z[None])[0], z, jac=jacobian, bounds=(-bound, bound), max_nfev=max_evaluations
        )
        if best is None or solution.cost < best.cost:
            best = solution
    return best.x, best.fun[:n], best.jac[:n], runs[0]


def laplace_covariance(r: np.ndarray, J: np.ndarray) -> np.ndarray:
    """(JᵀJ + I)⁻¹ (22, 22) with the translation and rotation rows of the residuals r (n,) and their
    Jacobian J (n, 22) scaled by each group's RMS residual: the noise the fit implies."""
    groups = np.arange(len(r)) % 6 < 3
    scale = np.where(groups, np.sqrt(np.mean(r[groups] ** 2)), np.sqrt(np.mean(r[~groups] ** 2)))
    Js = J / scale[:, None]
    return np.linalg.inv(Js.T @ Js + np.eye(J.shape[1]))
