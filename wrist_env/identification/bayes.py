"""A Bayesian calibrator: the posterior of the 22 materials given a participant's calibration trial.

Target: `likelihood.log_likelihood` of the per-frame scaphoid and lunate DOF residuals (noise scales
of translations and rotations integrated out) + `likelihood.log_prior` (Table 2, z units, |z| ≤ 3).

Sampler: emcee's ensemble MCMC (Foreman-Mackey et al. 2013, PASP 125:306), chosen because its
ensemble is a batch: every step moves all walkers at once, so one step is one batched solver call
(`vectorize=True`), the way the solver is fast; it is pure NumPy. Its moves are differential
evolution (80 %) and DE snooker (20 %) (ter Braak & Vrugt 2008, Stat Comput 18:435), which mix
better than the default stretch move in 22 dimensions, and `prior_refresh` (a share `PRIOR_REFRESH`),
which redraws one material from its prior: a slack ligament's reference strain is a hinge (flat
likelihood on the slack side, a cliff where it engages) that the ensemble's small differences near
the MAP do not cross. Gradient samplers (NUTS) need derivatives
the explicit solver does not give; nested sampling (dynesty) and flow-preconditioned SMC (pocomc,
which needs torch) spend more simulations or dependencies on one posterior.

Or (sampler="smc", `sample_smc`): adaptive tempered sequential Monte Carlo (Del Moral, Doucet &
Jasra 2006, JRSS B 68:411) by SMCPy (NASA): each stage's moves are one batched call per step, and
it estimates the evidence. From the prior it did not find the narrow basin of the best fit (docs/history.md),
so it bridges from a `DefensiveStart` around the MAP. SMCPy is chosen over `particles` (pins
numpy < 2) and pocomc (torch).

Start: the walkers are drawn around the MAP (`map_estimate`: the best of `MAP_STARTS` trust-region
Gauss–Newton runs on the residuals at the 4DCT noise and the prior) from its Laplace covariance
(`laplace_covariance`); the first half of the steps is burn-in and discarded.

Diagnostics (`Posterior`): the integrated autocorrelation time τ of each material (emcee), the
effective sample size (kept samples / τ), split R̂ over the walkers (Gelman et al., BDA3 §11.4;
the stricter of the two on short chains) and the acceptance rate. Predictive bands: `PREDICTIVE_DRAWS` posterior draws simulated on the
calibration and the held-out trial, 5/50/95 % of each DOF at each frame.
"""

from __future__ import annotations

import copy
import time

import numpy as np

from wrist_env import design, table2
from wrist_env.cost import COST_BONES
from wrist_env.errors import ParticipantError
from wrist_env.frames import pose_to_dof
from wrist_env.identification import likelihood
from wrist_env.identification.map import laplace_covariance, map_estimate
from wrist_env.identification.mcmc import log_likelihood, log_probability, sample
from wrist_env.identification.posterior import Posterior
from wrist_env.identification.settings import SamplerSettings
from wrist_env.identification.smc import DefensiveStart, sample_smc
from wrist_env.model import BONES
from wrist_env.motions import TRIAL_MOTIONS
from wrist_env.participants import builtin
from wrist_env.task import Task, cost_poses, task

PREDICTIVE_DRAWS = 32


TRIALS = ("built-in", "model")


def model_trials(t: Task, seed: int) -> Task:
    """A copy of a built-in participant's task whose reference kinematics are the calibration model's own
    run of the hidden truth on the task's capitate motion, with the synthetic trials' tracking noise
    (`builtin.tracking_noise`, drawn from `seed`): data without model error, to tell the calibrator's
    honesty from the model's fidelity."""
    if t.participant not in builtin.BUILTIN:
        raise ParticipantError(
            f"model trials need a hidden truth; {t.participant!r} is not a built-in participant {builtin.BUILTIN}"
        )
    run = t.evaluate(builtin.truth(t.participant))
    if run.failed:
        raise RuntimeError(f"{t.participant} {t.motion}: the hidden truth's run failed ({run.result.message})")
    rng = np.random.default_rng([seed, TRIAL_MOTIONS.index(t.motion)])
    poses = cost_poses(run.result.poses)
    out = copy.copy(t)
    out.reference = np.stack(
        [builtin.tracking_noise(p, t.model.centroid[BONES.index(b)], rng) for b, p in zip(COST_BONES, poses)]
    )
    return out


def _tasks(participant: str, trials: str, seed: int) -> tuple[Task, Task]:
    """The calibration and held-out tasks: the participant's trials or `model_trials`."""
    if trials not in TRIALS:
        raise ValueError(f"trials must be one of {TRIALS}, but got {trials!r}")
    if trials == "model" and participant not in builtin.BUILTIN:  # before building its model
        raise ParticipantError(
            f"model trials need a hidden truth; {participant!r} is not a built-in participant {builtin.BUILTIN}"
        )
    pair = task(participant, "calibrate"), task(participant, "validate")
    return pair if trials == "built-in" else tuple(model_trials(t, seed) for t in pair)


def calibrate(
    participant: str,
    seed: int = 0,
    settings: SamplerSettings | None = None,
    *,
    progress: bool = False,
    trials: str = "built-in",
) -> Posterior:
    """Sample the posterior of `participant`'s 22 materials given its calibration trial (see the module doc)
    with the sampler and settings of `settings` (default `SamplerSettings()`: emcee at its defaults);
    trials="model" calibrates against `model_trials` instead."""
    settings = SamplerSettings() if settings is None else settings
    if not isinstance(settings, SamplerSettings):
        raise TypeError(f"settings must be a SamplerSettings, but got {type(settings).__name__}")
    start_time = time.perf_counter()
    calibration, held_out = _tasks(participant, trials, seed)
    rng = np.random.default_rng(seed)
    map_z, r, J, runs = map_estimate(calibration, settings.map_starts, seed=seed)
    counter, extra = [runs], {}
    if settings.sampler == "emcee":
        start = rng.multivariate_normal(map_z, laplace_covariance(r, J), size=settings.walkers)
        start = np.clip(start, -0.99 * likelihood.BOUND_Z, 0.99 * likelihood.BOUND_Z)
        log_prob_fn = log_probability(calibration, counter)
        out = sample(log_prob_fn, start, settings.steps, seed, progress, settings.prior_refresh)
        samples, log_prob = out["chain"].reshape(-1, design.N_MATERIAL), out["log_prob"].ravel()
        diagnostics = out["autocorr"], out["ess"], out["rhat"], out["acceptance"]
    else:
        start = DefensiveStart(map_z, laplace_covariance(r, J))
        log_like = log_likelihood(calibration, counter)
        out = sample_smc(log_like, design.N_MATERIAL, settings.particles, settings.mcmc_steps, seed, progress, start)
        samples = out["samples"]
        log_prob = out["log_likelihood"] + likelihood.log_prior(samples)
        distinct = float(len(np.unique(samples, axis=0)))
        nan = np.full(design.N_MATERIAL, np.nan)
        diagnostics = nan, np.full(design.N_MATERIAL, distinct), nan, float(out["acceptance"].mean())
        extra = {"log_evidence": out["log_evidence"], "stages": len(out["phi"]) - 1}
    draws = samples[rng.choice(len(samples), min(PREDICTIVE_DRAWS, len(samples)), replace=False)]
    predictive, observed, noise = [], [], None
    for motion, t in (("calibrate", calibration), ("validate", held_out)):
        evaluations = t.evaluate_batch([table2.with_z(design.population(), z) for z in draws])
        counter[0] += len(draws)
        ok = [e for e in evaluations if not e.failed]
        dof = np.stack([_dof(t, cost_poses(e.result.poses)) for e in ok])
        predictive.append(np.quantile(dof, [0.05, 0.5, 0.95], axis=0))
        observed.append(_dof(t, t.reference))
        if motion == "calibrate":
            noise = np.median([likelihood.noise_scale(likelihood.residuals(t, e.result.poses)) for e in ok], axis=0)
    return Posterior(
        participant,
        int(seed),
        samples,
        log_prob,
        map_z,
        *diagnostics,
        noise,
        counter[0],
        time.perf_counter() - start_time,
        np.stack(predictive),
        np.stack(observed),
        trials,
        settings.sampler,
        **extra,
        settings=settings.record(),
        model_hash=calibration.model.source_hash,
    )


def _dof(t: Task, poses: np.ndarray) -> np.ndarray:
    """DOF (2, n_frames, 6) of cost-bone poses (2, n_frames, 4, 4) at their centroids (mm, deg)."""
    return pose_to_dof(poses, t.reference_points[:, None, :])
