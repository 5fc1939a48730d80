"""Can a likelihood carry the capitate's tracking noise? The truth's deficit under four likelihoods.

On the built-in trials the hidden truth fits worse than the MAP (`experiments/research/model_error.py`: the
calibration model is driven by the trial's noisy capitate poses). This script measures, for P1–P3,
the log posterior of the truth minus that of the MAP (the best of `settings.MAP_STARTS` Gauss–Newton
runs, seed 0) under:

- jeffreys: the Bayesian calibrator's likelihood (`likelihood.log_likelihood`: Gaussian, the noise
  scales of translations and rotations integrated out under Jeffreys' prior);
- gaussian: Gaussian with the trials' own tracking noise per DOF (0.2 mm / √3, 0.5° / √3) known;
- frame_t: a frame's 12 residuals multivariate Student-t (a per-frame scale mixture: a frame may be
  off as a whole), the two noise scales integrated out under Jeffreys' prior and ν under
  Gamma(2, 0.1) (Juárez & Steel 2010, J Bus Econ Stat 28:52), by quadrature;
- eiv: errors in variables, linearized: per frame the residuals' covariance is the tracking noise's
  plus D Dᵀ, D (12 × 6) the scaphoid's and lunate's response to one SD of the capitate's tracking
  noise along each of its six axes (about its centroid). D comes from the force kernels' tangent
  at the frame's equilibrium (`equilibrium._jacobian`, the membrane's free nodes included:
  δq = −K⁻¹ ∂F/∂capitate), no simulation, and is checked against simulations with every frame's
  capitate moved ±1 SD along each axis (correlation and RMS of the two);
- marginal_K: errors in variables by simulation: the Gaussian likelihood at the trials' tracking
  noise averaged, frame by frame, over K runs driven by the trial's capitate with fresh tracking
  noise (the capitate's pose given its observation, under a flat prior), K = 32, 128, 512 (nested
  draws): an unbiased estimate of the likelihood with the capitate's noise marginalized out (frames
  taken as independent), at K× a run's cost.

A likelihood that accounts for the model error would put the truth where a posterior draw sits:
log density ~11 ± 3 nats below the mode in 22 dimensions (χ²₂₂ / 2). Writes
`leaderboards/posterior/capitate_likelihood.csv` (deficits) and `capitate_response.csv` (the check).

Run: `python experiments/research/capitate_likelihood.py [P1 P2 P3]` (~10 min a participant: the MAP search
and 1,024 runs).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pandas as pd
from scipy.spatial.transform import Rotation
from scipy.special import gammaln, logsumexp
from scipy.stats import gamma

from wrist_env import design, table2
from wrist_env.identification import likelihood
from wrist_env.identification.map import map_estimate
from wrist_env.model import BONES, CAPITATE
from wrist_env.participants import builtin, registry
from wrist_env.participants.builtin import TRACKING_NOISE_DEG, TRACKING_NOISE_MM
from wrist_env.solver import equilibrium
from wrist_env.solver.drivers import experimental
from wrist_env.solver.rigid import pose_translation
from wrist_env.solver.simulate import simulate, stiffness
from wrist_env.task import Task, task

OUT = Path(__file__).resolve().parents[2] / "leaderboards" / "posterior"
AXIS_SD = np.r_[np.full(3, TRACKING_NOISE_MM), np.radians(np.full(3, TRACKING_NOISE_DEG))] / np.sqrt(3)
"""The tracking noise per axis (mm, rad): `builtin.tracking_noise` is isotropic with these RMS totals."""
TRACKING_SD = np.r_[TRACKING_NOISE_MM / likelihood.NOISE[:3], TRACKING_NOISE_DEG / likelihood.NOISE[3:]] / np.sqrt(3)
"""The same per DOF residual, in `likelihood.NOISE` units (both 1/√3)."""
LOG_S = np.linspace(np.log(0.05), np.log(50.0), 120)
NU = np.exp(np.linspace(0.0, np.log(300.0), 40))
LOG_W_NU = gamma(2.0, scale=10.0).logpdf(NU) + np.log(NU) + np.log(np.diff(np.log(NU)).mean())


def moved(R0: np.ndarray, x0: np.ndarray, centroid: np.ndarray, dc: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Rotations and centres of mass with the capitate shifted by dc[:3] (mm) and turned by the rotation
    vector dc[3:] (rad) about its centroid (world, mm)."""
    R, x = R0.copy(), x0.copy()
    turn = Rotation.from_rotvec(dc[3:]).as_matrix()
    R[CAPITATE] = turn @ R0[CAPITATE]
    x[CAPITATE] = turn @ (x0[CAPITATE] - centroid) + centroid + dc[:3]
    return R, x


def response(t: Task, d: design.Design, result) -> np.ndarray:
    """D (n_frames, 12, 6): the residuals' (`likelihood.residuals`, frame-major: bone, DOF) linear response
    to one SD of the capitate's tracking noise per axis, from the tangent at each frame."""
    p, cap = t.prepared, BONES.index("capitate")
    free, n = equilibrium._unknowns(t.model, t.driver)
    k_design = stiffness(p, d)
    base = likelihood.residuals(t, result.poses)
    D, out, h, eps = np.zeros((t.driver.n_frames, 12, 6)), np.zeros(n), 1e-6, 1e-3
    for f in range(t.driver.n_frames):
        args = equilibrium._frame_args(p, k_design, free, t.driver, result, f)
        start = args[0]
        R0, x0 = start.R, start.x
        K = equilibrium._jacobian(np.zeros(n), *args, equilibrium.JACOBIAN_STEP)
        T = result.poses[f, cap]
        centroid = T[:3, :3] @ t.model.centroid[cap] + T[:3, 3]
        dF = np.zeros((n, 6))
        for k in range(6):
            for sign in (1.0, -1.0):
                R, x = moved(R0, x0, centroid, sign * h * np.eye(6)[k])
                dF[:, k] += (
                    sign * equilibrium._residual(np.zeros(n), start._replace(R=R, x=x), *args[1:], out) / (2 * h)
                )
        dq = -np.linalg.lstsq(K, dF * AXIS_SD, rcond=1e-10)[0]
        for k in range(6):
            R, x, _ = equilibrium.moved_state(eps * dq[:, k], start, False)
            poses = result.poses.copy()
            poses[f, :, :3, :3] = R
            poses[f, :, :3, 3] = pose_translation(R, x, p.bodies.com0)
            D[f, :, k] = ((likelihood.residuals(t, poses)[:, f] - base[:, f]) / eps).ravel()
    return D


def simulated_response(t: Task, d: design.Design, k: int) -> np.ndarray:
    """(n_frames, 12): the residuals' change per SD with every frame's capitate moved ±1 SD along axis k."""
    drv, cap = t.driver, BONES.index("capitate")
    com0 = t.model.com[cap]
    centroid = np.einsum("fij,j->fi", drv.rotation, t.model.centroid[cap] - com0) + drv.com
    runs = []
    for sign in (1.0, -1.0):
        dc = sign * AXIS_SD[k] * np.eye(6)[k]
        turn = Rotation.from_rotvec(dc[3:]).as_matrix()
        poses = np.tile(np.eye(4), (drv.n_frames, 1, 1))
        poses[:, :3, :3] = np.einsum("ij,fjk->fik", turn, drv.rotation)
        com = np.einsum("ij,fj->fi", turn, drv.com - centroid) + centroid + dc[:3]
        poses[:, :3, 3] = com - np.einsum("fij,j->fi", poses[:, :3, :3], com0)
        run = simulate(t.model, d, experimental(t.model, poses), prepared=t.prepared)
        runs.append(likelihood.residuals(t, run.poses))
    return np.transpose((runs[0] - runs[1]) / 2.0, (1, 0, 2)).reshape(drv.n_frames, 12)


def _frames(r: np.ndarray) -> np.ndarray:
    """Residuals (2, n_frames, 6) as (n_frames, 12), the order of `response`'s rows."""
    return np.transpose(r, (1, 0, 2)).reshape(r.shape[1], 12)


def gaussian(r: np.ndarray, D: np.ndarray | None = None) -> float:
    """Σ_frames log N(r_f; 0, diag(TRACKING_SD²) + D_f D_fᵀ) (D None: no capitate term)."""
    rf, var = _frames(r), np.tile(TRACKING_SD**2, 2)
    total = 0.0
    for f in range(len(rf)):
        C = np.diag(var) + (0.0 if D is None else D[f] @ D[f].T)
        total += -0.5 * np.linalg.slogdet(C)[1] - 0.5 * rf[f] @ np.linalg.solve(C, rf[f])
    return float(total)


def frame_t(r: np.ndarray) -> float:
    """Per-frame multivariate Student-t, the two noise scales (Jeffreys) and ν (Gamma(2, 0.1)) integrated out."""
    qt, qr = np.sum(r[..., :3] ** 2, axis=(0, 2)), np.sum(r[..., 3:] ** 2, axis=(0, 2))
    s_t, s_r = np.exp(LOG_S)[:, None, None, None], np.exp(LOG_S)[None, :, None, None]
    nu = NU[None, None, :, None]
    q = qt / s_t**2 + qr / s_r**2
    log_f = (
        gammaln((nu + 12) / 2)
        - gammaln(nu / 2)
        - 6 * np.log(nu * np.pi)
        - 6 * np.log(s_t * s_r)
        - (nu + 12) / 2 * np.log1p(q / nu)
    )
    return float(logsumexp(log_f.sum(-1) + LOG_W_NU[None, None, :]))


MARGINAL_DRAWS = (32, 128, 512)


def noisy_drivers(t: Task, k: int, seed: int = 1) -> list:
    """k drivers: the trial's capitate poses with fresh tracking noise (`builtin.tracking_noise`)."""
    observed = registry.trial(t.participant, "calibrate").pose("capitate")
    centroid, rng = t.model.centroid[BONES.index("capitate")], np.random.default_rng(seed)
    return [experimental(t.model, builtin.tracking_noise(observed, centroid, rng)) for _ in range(k)]


def marginal(t: Task, d: design.Design, drivers: list) -> dict[str, float]:
    """{"marginal_<K>": Σ_frames log of the mean over the first K drivers of the frame's Gaussian likelihood
    at the tracking noise} for K in `MARGINAL_DRAWS` (a failed run contributes zero likelihood)."""
    var = np.tile(TRACKING_SD**2, 2)
    per_run = []
    for driver in drivers:
        run = simulate(t.model, d, driver, prepared=t.prepared)
        if not run.ok:
            per_run.append(np.full(driver.n_frames, -np.inf))
            continue
        r = _frames(likelihood.residuals(t, run.poses))
        per_run.append(-0.5 * np.sum(r**2 / var + np.log(2 * np.pi * var), axis=1))
    L = np.array(per_run)
    return {f"marginal_{k}": float(np.sum(logsumexp(L[:k], axis=0) - np.log(k))) for k in MARGINAL_DRAWS}


def rows(name: str) -> tuple[list[dict], list[dict]]:
    t = task(name, "calibrate")
    z_truth = table2.z_scores(builtin.truth(name))
    map_z, *_ = map_estimate(t)
    values, check, drivers = {}, [], noisy_drivers(t, max(MARGINAL_DRAWS))
    for label, z in (("truth", z_truth), ("MAP", map_z)):
        d = table2.with_z(design.population(), z)
        run = t.evaluate(d).result
        r, D = likelihood.residuals(t, run.poses), response(t, d, run)
        prior = float(likelihood.log_prior(z))
        values[label] = {
            "jeffreys": likelihood.log_likelihood(r) + prior,
            "gaussian": gaussian(r) + prior,
            "frame_t": frame_t(r) + prior,
            "eiv": gaussian(r, D) + prior,
        }
        values[label].update({k: v + prior for k, v in marginal(t, d, drivers).items()})
        if label == "truth":
            for k in range(6):
                sim, lin = simulated_response(t, d, k), D[:, :, k]
                check.append(
                    {
                        "participant": name,
                        "axis": ("x", "y", "z", "rx", "ry", "rz")[k],
                        "rms_simulated": float(np.sqrt(np.mean(sim**2))),
                        "rms_tangent": float(np.sqrt(np.mean(lin**2))),
                        "correlation": float(np.corrcoef(sim.ravel(), lin.ravel())[0, 1]),
                    }
                )
    out = [
        {"participant": name, "likelihood": k, "truth_minus_map": values["truth"][k] - values["MAP"][k]}
        for k in values["truth"]
    ]
    print(name, ", ".join(f"{r['likelihood']} {r['truth_minus_map']:.1f}" for r in out), flush=True)
    return out, check


def main(names: list[str]) -> None:
    deficits, checks = [], []
    for name in names:
        a, b = rows(name)
        deficits += a
        checks += b
    OUT.mkdir(parents=True, exist_ok=True)
    pd.DataFrame(deficits).to_csv(OUT / "capitate_likelihood.csv", index=False, float_format="%.2f")
    pd.DataFrame(checks).to_csv(OUT / "capitate_response.csv", index=False, float_format="%.3f")
    print(pd.DataFrame(deficits).pivot(index="likelihood", columns="participant", values="truth_minus_map").round(1))
    print(pd.DataFrame(checks).round(2).to_string(index=False))
    print(f"written to {OUT / 'capitate_likelihood.csv'} and {OUT / 'capitate_response.csv'}")


if __name__ == "__main__":
    main(sys.argv[1:] or list(builtin.BUILTIN))
