"""A Bayesian calibrator: the posterior of the 22 materials given a participant's calibration trial.

Target: `posterior.log_likelihood` of the per-frame scaphoid and lunate DOF residuals (noise scales
of translations and rotations integrated out) + `posterior.log_prior` (Table 2, z units, |z| ≤ 3).

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
it estimates the evidence. From the prior it did not find the narrow basin of the best fit (README),
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

import time
from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from wrist_env import design, posterior
from wrist_env.envs.task import Task, cost_poses, task
from wrist_env.errors import StoreError
from wrist_env.frames import pose_to_dof
from wrist_env.io import load_dataclass, save_dataclass
from wrist_env.trial import TRIAL_MOTIONS

WALKERS = 48
STEPS = 1200
"""Ensemble steps: at 300 the chains were overconfident even on the model's own trials (README); ~12 min a run."""
PRIOR_REFRESH = 0.2
"""Share of emcee's moves that are `prior_refresh`; the rest DE (80 %) and DE snooker (20 %)."""
MAP_STARTS = 24
"""Gauss–Newton starts of the MAP search: on P1's model trials (seed 0) 10 of 24 random starts reached
the basin of the best fit (objective 35) and 14 stopped at 91–146; 8 starts all missed it there."""
FD_STEP_Z = 0.1
"""Forward-difference step of the MAP search's Jacobian (SD units)."""
FAILED_RESIDUAL = 30.0
"""Residual (noise units) of every DOF of a failed run in the MAP search."""
PREDICTIVE_DRAWS = 32
PARTICLES = 256
MCMC_STEPS = 5
"""Random-walk Metropolis steps per particle and SMC stage."""
START_DF = 5
START_SCALE = 1.5
"""SMC's start around the MAP: Student-t degrees of freedom and the Laplace covariance's scale (SD)."""
PRIOR_SHARE = 0.2
"""The prior's share of SMC's defensive start."""
TARGET_ESS = 0.5
"""Each SMC stage's effective sample size after reweighting, a share of the particles."""
QUANTILES = (0.05, 0.25, 0.5, 0.75, 0.95)


@dataclass(frozen=True)
class Posterior:
    """Posterior samples of the 22 materials (z units) and their diagnostics.

    samples (n, 22): emcee's kept chain (walkers and steps flattened) or SMC's final particles;
    log_prob (n,). map_z (22,): the start (MAP at the 4DCT noise; SMC's `DefensiveStart` is centred there).
    autocorr (22,): τ in steps (emcee; NaN for SMC); ess (22,): kept samples / τ (τ from a chain
    shorter than 50 τ is low, so this is then an upper bound), for SMC the distinct final particles;
    rhat (22,): split R̂ over walkers (emcee; NaN for SMC); acceptance: mean acceptance rate (SMC:
    the mean share of particles a stage's moves changed); noise (2,): posterior median of the
    translation (mm) and rotation (deg) noise scale; evaluations: simulations run.
    predictive (2 motions, 3 quantiles 5/50/95 %, 2 bones, n_frames, 6) DOF (mm, deg) of the
    calibration and held-out trial; observed (2, 2, n_frames, 6) the trials' own DOF.
    trials: "built-in" (the participant's trials) or "model" (`model_trials`: no model error).
    sampler: "emcee" or "smc"; log_evidence and stages: SMC's log marginal likelihood and tempering stages.
    settings: the sampler's settings (`sampler_settings`); None in files saved before they were recorded.
    """

    participant: str
    seed: int
    samples: np.ndarray
    log_prob: np.ndarray
    map_z: np.ndarray
    autocorr: np.ndarray
    ess: np.ndarray
    rhat: np.ndarray
    acceptance: float
    noise: np.ndarray
    evaluations: int
    wall_seconds: float
    predictive: np.ndarray
    observed: np.ndarray
    trials: str = "built-in"
    sampler: str = "emcee"
    log_evidence: float = float("nan")
    stages: int = 0
    settings: dict | None = None

    ARRAYS = ("samples", "log_prob", "map_z", "autocorr", "ess", "rhat", "noise", "predictive", "observed")

    @property
    def mean(self) -> np.ndarray:
        return self.samples.mean(axis=0)

    def quantiles(self, q=QUANTILES) -> np.ndarray:
        """Per-material quantiles (len(q), 22) in z units."""
        return np.quantile(self.samples, q, axis=0)

    def interval(self, level: float) -> tuple[np.ndarray, np.ndarray]:
        """Central credible interval (lower, upper), each (22,), z units."""
        return tuple(np.quantile(self.samples, [0.5 - level / 2, 0.5 + level / 2], axis=0))

    def covers(self, z_true: np.ndarray, level: float) -> np.ndarray:
        """Which of the 22 true values lie inside the central `level` interval."""
        lo, hi = self.interval(level)
        return (z_true >= lo) & (z_true <= hi)

    def save(self, path: str | Path) -> Path:
        """`<path>.npz` (arrays; the samples as float32: 1e-7 SD, half the file) and `<path>.json`
        (the other fields), atomically (`io.save_dataclass`)."""
        path = Path(path)
        save_dataclass(replace(self, samples=self.samples.astype(np.float32)), path)
        return path.with_suffix(".npz")

    @classmethod
    def load(cls, path: str | Path) -> Posterior:
        return load_dataclass(cls, path)


def map_estimate(
    calibration: Task, starts: int = MAP_STARTS, seed: int = 0, max_evaluations: int = 40
) -> tuple[np.ndarray, np.ndarray, np.ndarray, int]:
    """(MAP z (22,), its residuals (n,), their Jacobian (n, 22), simulations run): the best of
    trust-region Gauss–Newton runs (SciPy's `least_squares`, TRF, |z| ≤ 3) on [residuals; z] from the
    population design and `starts` − 1 draws of N(0, 0.7²) (the misfit is multimodal: on P1, 1 of 6
    random starts reached the basin of the hidden truth; see `MAP_STARTS`)."""
    from scipy.optimize import least_squares

    base, runs = design.population(), [0]
    n = 2 * calibration.reference.shape[1] * 6

    def stacked(Z):
        evaluations = calibration.evaluate_batch([design.with_z(base, z) for z in Z])
        runs[0] += len(Z)
        out = []
        for z, e in zip(Z, evaluations):
            r = np.full(n, FAILED_RESIDUAL) if e.failed else posterior.residuals(calibration, e.result.poses).ravel()
            out.append(np.concatenate([r, z]))
        return np.array(out)

    def jacobian(z):
        R = stacked(np.vstack([z, z + FD_STEP_Z * np.eye(len(z))]))
        return ((R[1:] - R[0]) / FD_STEP_Z).T

    rng = np.random.default_rng(seed)
    z0 = np.vstack([np.zeros(design.N_MATERIAL), rng.normal(0.0, 0.7, (starts - 1, design.N_MATERIAL))])
    bound = posterior.BOUND_Z
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


def log_likelihood(calibration: Task, counter: list | None = None) -> Callable[[np.ndarray], np.ndarray]:
    """The batched log likelihood (W, 22) → (W,) of z on the calibration trial; −inf where a run fails."""
    base = design.population()

    def log_like(Z):
        Z = np.atleast_2d(Z)
        evaluations = calibration.evaluate_batch([design.with_z(base, z) for z in Z])
        if counter is not None:
            counter[0] += len(Z)
        return np.array(
            [
                -np.inf if e.failed else posterior.log_likelihood(posterior.residuals(calibration, e.result.poses))
                for e in evaluations
            ]
        )

    return log_like


def log_probability(calibration: Task, counter: list | None = None) -> Callable[[np.ndarray], np.ndarray]:
    """The batched log posterior (W, 22) → (W,) of z on the calibration trial (no run outside |z| ≤ 3)."""
    log_like = log_likelihood(calibration, counter)

    def log_prob(Z):
        Z = np.atleast_2d(Z)
        out = posterior.log_prior(Z)
        inside = np.flatnonzero(np.isfinite(out))
        if len(inside):
            out[inside] += log_like(Z[inside])
        return out

    return log_prob


def prior_refresh(coords: np.ndarray, random) -> tuple[np.ndarray, np.ndarray]:
    """An emcee proposal (`emcee.moves.MHMove`): one material per walker drawn afresh from its prior,
    a Metropolis-within-Gibbs independence move. Returns the proposal (W, 22) and the Hastings
    factors log π(old) − log π(new), which cancel the prior in the acceptance: a ligament that is
    slack over a range of its reference strain is accepted anywhere in that range in one move."""
    n, dim = coords.shape
    rows, which = np.arange(n), random.randint(dim, size=n)
    old = coords[rows, which]
    new = posterior.material_prior().rvs(size=n, random_state=random)
    factors = np.where(np.abs(old) <= posterior.BOUND_Z, 0.5 * (new**2 - old**2), -np.inf)
    out = coords.copy()
    out[rows, which] = new
    return out, factors


def sample(
    log_prob, start: np.ndarray, steps: int, seed: int, progress: bool = False, refresh: float = PRIOR_REFRESH
) -> dict:
    """Run emcee from `start` (walkers, dim) for `steps`, a share `refresh` of the moves `prior_refresh`;
    the second half kept.

    Returns {"chain": (kept, walkers, dim), "log_prob": (kept, walkers), "acceptance",
    "autocorr" (dim,), "ess" (dim,), "rhat" (dim,)}.
    """
    import logging

    import emcee

    logging.getLogger("emcee").setLevel(logging.ERROR)  # a short chain's τ is reported, not warned about
    walkers, dim = start.shape
    moves = [
        (emcee.moves.DEMove(), 0.8 * (1 - refresh)),
        (emcee.moves.DESnookerMove(), 0.2 * (1 - refresh)),
    ] + ([(emcee.moves.MHMove(prior_refresh), refresh)] if refresh > 0 else [])
    sampler = emcee.EnsembleSampler(walkers, dim, log_prob, moves=moves, vectorize=True)
    sampler.random_state = np.random.RandomState(seed).get_state()
    sampler.run_mcmc(start, steps, progress=progress)
    burn = steps // 2
    chain = sampler.get_chain(discard=burn)
    moved = np.ptp(chain, axis=0).min(axis=1) > 0  # a walker that never moved has no autocorrelation
    tau = np.maximum(emcee.autocorr.integrated_time(chain[:, moved], quiet=True), 1.0)
    return {
        "chain": chain,
        "log_prob": sampler.get_log_prob(discard=burn),
        "acceptance": float(np.mean(sampler.acceptance_fraction)),
        "autocorr": tau,
        "ess": chain.shape[0] * walkers / tau,
        "rhat": split_rhat(chain),
    }


FAILED_LOG_LIKELIHOOD = -1e6
"""SMC's log likelihood of a failed run: finite (a tempered −inf·0 is NaN) and negligible at any φ > 10⁻³."""


class DefensiveStart:
    """An SMC start: (1 − `PRIOR_SHARE`)·Student-t (ν = `START_DF`, centre `mean`, scale matrix
    `START_SCALE`²·`cov`) truncated to the prior box, plus `PRIOR_SHARE`·prior, the defensive mixture
    of Hesterberg (1995, Technometrics 37:185): heavy tails and the prior so that it covers what the
    Laplace approximation misses. rvs(n, random_state) → (n, 22); logpdf(x (n, 22)) → (n,), normalized."""

    def __init__(self, mean: np.ndarray, cov: np.ndarray):
        from scipy.stats import multivariate_t

        self.student = multivariate_t(mean, START_SCALE**2 * cov, df=START_DF)
        self.prior = posterior.material_prior()
        inside = posterior.in_box(self.student.rvs(100_000, random_state=np.random.default_rng(0)))
        self.log_inside = np.log(max(inside.mean(), 1e-5))  # the truncated t's normalizer, Monte Carlo

    def rvs(self, n: int, random_state=None) -> np.ndarray:
        rng = np.random.default_rng(random_state)
        out = self.prior.rvs(size=(n, len(self.student.loc)), random_state=rng)
        from_t = np.flatnonzero(rng.random(n) >= PRIOR_SHARE)
        draws = np.empty((0, out.shape[1]))
        while len(draws) < len(from_t):
            batch = self.student.rvs(4 * len(from_t) + 16, random_state=rng)
            draws = np.vstack([draws, batch[posterior.in_box(batch)]])
        out[from_t] = draws[: len(from_t)]
        return out

    def logpdf(self, x: np.ndarray) -> np.ndarray:
        x = np.atleast_2d(x)
        student = np.log1p(-PRIOR_SHARE) + self.student.logpdf(x) - self.log_inside
        prior = np.log(PRIOR_SHARE) + self.prior.logpdf(x).sum(axis=1)
        return np.where(posterior.in_box(x), np.logaddexp(student, prior), -np.inf)


def sample_smc(
    log_like, dim: int, particles: int, mcmc_steps: int, seed: int, progress: bool = False, start=None
) -> dict:
    """Adaptive tempered SMC (SMCPy) to the posterior, from the prior (`posterior.log_prior`) or along
    the geometric bridge from `start` (an object with rvs and a normalized logpdf, e.g. `DefensiveStart`).

    log_like: batched log likelihood (n, dim) → (n,). Each stage moves φ (the bridge's exponent) so
    that the reweighted particles keep an ESS of `TARGET_ESS`, resamples, and moves every particle
    `mcmc_steps` random-walk Metropolis steps with the particles' covariance. Returns {"samples"
    (particles, dim), "log_likelihood" (particles,), "phi" (stages + 1,), "acceptance" (stages,): the
    share of particles each stage's moves changed, "log_evidence"}.
    """
    from smcpy import AdaptiveSampler, VectorMCMC, VectorMCMCKernel
    from smcpy.paths import GeometricPath

    class Batched:  # SMCPy's log-likelihood interface: built from (model, data, args), called on (n, dim)
        def __init__(self, model, data, args):
            self.model = model

        def __call__(self, inputs):
            out = np.asarray(self.model(inputs), dtype=np.float64)
            return np.where(np.isfinite(out), out, FAILED_LOG_LIKELIHOOD)

    priors = [posterior.material_prior() for _ in range(dim)]
    mcmc = VectorMCMC(log_like, None, priors, log_like_func=Batched)
    names = [f"z{i}" for i in range(dim)]
    path = GeometricPath(proposal=start)
    kernel = VectorMCMCKernel(mcmc, param_order=names, path=path, rng=np.random.default_rng(seed))
    sampler = AdaptiveSampler(kernel, show_progress_bar=progress)
    steps, log_evidence = sampler.sample(particles, mcmc_steps, target_ess=TARGET_ESS)
    last = steps[-1]
    return {
        "samples": np.column_stack([last.param_dict[k] for k in names]),
        "log_likelihood": np.asarray(last.log_likes).ravel(),
        "phi": np.asarray(sampler.phi_sequence, dtype=np.float64),
        "acceptance": np.array([step.attrs["mutation_ratio"] for step in list(steps)[1:]], dtype=np.float64),
        "log_evidence": float(np.ravel(log_evidence)[-1]),
    }


def split_rhat(chain: np.ndarray) -> np.ndarray:
    """Split R̂ (dim,) of a chain (steps, chains, dim): each chain's halves as two chains (BDA3 §11.4)."""
    n = chain.shape[0] // 2
    halves = np.concatenate([chain[:n], chain[n : 2 * n]], axis=1)  # (n, 2·chains, dim)
    within = halves.var(axis=0, ddof=1).mean(axis=0)
    between = n * halves.mean(axis=0).var(axis=0, ddof=1)
    return np.sqrt(((n - 1) / n * within + between / n) / within)


TRIALS = ("built-in", "model")
SAMPLERS = ("emcee", "smc")


def model_trials(t: Task, seed: int) -> Task:
    """A copy of a built-in participant's task whose reference kinematics are the calibration model's own
    run of the hidden truth on the task's capitate motion, with the synthetic trials' tracking noise
    (`builtin.tracking_noise`, drawn from `seed`): data without model error, to tell the calibrator's
    honesty from the model's fidelity."""
    import copy

    from wrist_env.cost import COST_BONES
    from wrist_env.model import BONES
    from wrist_env.participants import builtin

    if t.participant not in builtin.BUILTIN:
        raise ValueError(f"model trials need a hidden truth; {t.participant!r} is not a built-in participant")
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
    pair = task(participant, "calibrate"), task(participant, "validate")
    return pair if trials == "built-in" else tuple(model_trials(t, seed) for t in pair)


def calibrate(
    participant: str,
    seed: int = 0,
    walkers: int = WALKERS,
    steps: int = STEPS,
    progress: bool = False,
    trials: str = "built-in",
    sampler: str = "emcee",
    particles: int = PARTICLES,
    mcmc_steps: int = MCMC_STEPS,
    map_starts: int = MAP_STARTS,
    prior_refresh_share: float = PRIOR_REFRESH,
) -> Posterior:
    """Sample the posterior of `participant`'s 22 materials given its calibration trial (see the module doc);
    trials="model" calibrates against `model_trials` instead; sampler="smc" runs `sample_smc` from the
    bridge from a `DefensiveStart` around the MAP with `particles` and `mcmc_steps` instead of emcee
    (`walkers`, `steps`, `prior_refresh_share` of its moves `prior_refresh`); map_starts: Gauss–Newton
    starts of the MAP search."""
    if sampler not in SAMPLERS:
        raise ValueError(f"sampler must be one of {SAMPLERS}, but got {sampler!r}")
    start_time = time.perf_counter()
    calibration, held_out = _tasks(participant, trials, seed)
    rng = np.random.default_rng(seed)
    map_z, r, J, runs = map_estimate(calibration, map_starts, seed=seed)
    counter, extra = [runs], {}
    if sampler == "emcee":
        start = rng.multivariate_normal(map_z, laplace_covariance(r, J), size=walkers)
        start = np.clip(start, -0.99 * posterior.BOUND_Z, 0.99 * posterior.BOUND_Z)
        out = sample(log_probability(calibration, counter), start, steps, seed, progress, prior_refresh_share)
        samples, log_prob = out["chain"].reshape(-1, design.N_MATERIAL), out["log_prob"].ravel()
        diagnostics = out["autocorr"], out["ess"], out["rhat"], out["acceptance"]
    else:
        start = DefensiveStart(map_z, laplace_covariance(r, J))
        log_like = log_likelihood(calibration, counter)
        out = sample_smc(log_like, design.N_MATERIAL, particles, mcmc_steps, seed, progress, start)
        samples = out["samples"]
        log_prob = out["log_likelihood"] + posterior.log_prior(samples)
        distinct = float(len(np.unique(samples, axis=0)))
        nan = np.full(design.N_MATERIAL, np.nan)
        diagnostics = nan, np.full(design.N_MATERIAL, distinct), nan, float(out["acceptance"].mean())
        extra = {"log_evidence": out["log_evidence"], "stages": len(out["phi"]) - 1}
    draws = samples[rng.choice(len(samples), min(PREDICTIVE_DRAWS, len(samples)), replace=False)]
    predictive, observed, noise = [], [], None
    for motion, t in (("calibrate", calibration), ("validate", held_out)):
        evaluations = t.evaluate_batch([design.with_z(design.population(), z) for z in draws])
        counter[0] += len(draws)
        ok = [e for e in evaluations if not e.failed]
        dof = np.stack([_dof(t, cost_poses(e.result.poses)) for e in ok])
        predictive.append(np.quantile(dof, [0.05, 0.5, 0.95], axis=0))
        observed.append(_dof(t, t.reference))
        if motion == "calibrate":
            noise = np.median([posterior.noise_scale(posterior.residuals(t, e.result.poses)) for e in ok], axis=0)
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
        sampler,
        **extra,
        settings=sampler_settings(sampler, walkers, steps, particles, mcmc_steps, map_starts, prior_refresh_share),
    )


def sampler_settings(
    sampler: str,
    walkers: int = WALKERS,
    steps: int = STEPS,
    particles: int = PARTICLES,
    mcmc_steps: int = MCMC_STEPS,
    map_starts: int = MAP_STARTS,
    prior_refresh_share: float = PRIOR_REFRESH,
) -> dict:
    """The settings that shape a run of `sampler` (a saved run records them; the study's table lists them)."""
    if sampler == "emcee":
        return {"walkers": walkers, "steps": steps, "map_starts": map_starts, "prior_refresh": prior_refresh_share}
    return {"particles": particles, "mcmc_steps": mcmc_steps, "map_starts": map_starts}


def _dof(t: Task, poses: np.ndarray) -> np.ndarray:
    """DOF (2, n_frames, 6) of cost-bone poses (2, n_frames, 4, 4) at their centroids (mm, deg)."""
    return pose_to_dof(poses, t.reference_points[:, None, :])


LEVELS = (0.5, 0.9)


def study(
    participants,
    seeds,
    out,
    *,
    walkers: int = WALKERS,
    steps: int = STEPS,
    progress: bool = True,
    on_run: Callable[[Posterior, bool], object] | None = None,
    report: str | Path | None = None,
    trials: str = "built-in",
    sampler: str = "emcee",
    particles: int = PARTICLES,
    mcmc_steps: int = MCMC_STEPS,
    map_starts: int = MAP_STARTS,
    prior_refresh_share: float = PRIOR_REFRESH,
):
    """A Bayesian calibration per participant and seed (`out/posterior_<P>_seed<s>.npz/.json`; a run
    already saved is loaded, not rerun), then the coverage table (one row per run: share of the 22 true
    z inside the 50 % and 90 % intervals, `truth_rank`, recovery of the posterior mean, the MAP and the
    population design, diagnostics) as `out/coverage.csv` and the figures; returns the table.
    on_run(posterior, loaded) is called after each run; report: the folder of the table and figures
    (default `out`); a saved run sampled with other settings is an error; trials: "built-in" or "model"
    (`model_trials`; files and figures get a `_model` suffix); sampler: "emcee" (walkers, steps) or
    "smc" (particles, mcmc_steps; suffix `_smc`); map_starts: Gauss–Newton starts of the MAP search; prior_refresh_share: emcee's share of
    `prior_refresh` moves."""
    import pandas as pd

    from wrist_env.figures.posterior import plot_intervals, plot_predictive
    from wrist_env.participants import builtin

    out = Path(out)
    suffix = ("" if trials == "built-in" else f"_{trials}") + ("" if sampler == "emcee" else f"_{sampler}")
    settings = sampler_settings(sampler, walkers, steps, particles, mcmc_steps, map_starts, prior_refresh_share)
    rows, posteriors = [], {}
    for participant in participants:
        truth = design.z_scores(builtin.truth(participant)) if participant in builtin.BUILTIN else None
        for seed in range(seeds) if isinstance(seeds, int) else seeds:
            path = out / f"posterior_{participant}_seed{seed}{suffix}.npz"
            loaded = path.exists()
            if loaded:
                post = Posterior.load(path)
                if post.settings is not None and post.settings != settings:
                    raise StoreError(
                        f"{path} was sampled with {post.settings}, not the {settings} asked for: "
                        "delete it or choose another output folder"
                    )
            else:
                post = calibrate(
                    participant,
                    seed,
                    progress=progress,
                    trials=trials,
                    sampler=sampler,
                    walkers=walkers,
                    steps=steps,
                    particles=particles,
                    mcmc_steps=mcmc_steps,
                    map_starts=map_starts,
                    prior_refresh_share=prior_refresh_share,
                )
                post.save(path)
            if on_run is not None:
                on_run(post, loaded)
            posteriors.setdefault(participant, []).append(post)
            row = {
                "participant": participant,
                "trials": post.trials,
                "seed": seed,
                "sampler": post.sampler,
                **settings,
                "evaluations": post.evaluations,
                "wall_seconds": round(post.wall_seconds, 1),
                "acceptance": post.acceptance,
                "ess_min": float(np.nanmin(post.ess)),
                "rhat_max": float(np.nanmax(post.rhat)) if post.sampler == "emcee" else np.nan,
                "noise_mm": post.noise[0],
                "noise_deg": post.noise[1],
                **({"stages": post.stages, "log_evidence": post.log_evidence} if post.sampler == "smc" else {}),
            }
            if truth is not None:
                for level in LEVELS:
                    row[f"coverage_{int(level * 100)}"] = float(post.covers(truth, level).mean())
                row.update(truth_rank(post, truth))
                row["recovery_mean"] = _rms(post.mean - truth)
                row["recovery_map"] = _rms(post.map_z - truth)
                row["recovery_population"] = _rms(truth)
            rows.append(row)
    table = pd.DataFrame(rows)
    report = out if report is None else Path(report)
    report.mkdir(parents=True, exist_ok=True)
    table.to_csv(report / f"coverage{suffix}.csv", index=False)
    for participant, posts in posteriors.items():
        truth = design.z_scores(builtin.truth(participant)) if participant in builtin.BUILTIN else None
        plot_intervals(posts, truth, report / f"posterior_intervals_{participant}{suffix}.png")
        plot_predictive(posts[0], report / f"posterior_predictive_{participant}{suffix}.png")
    return table


def truth_rank(post: Posterior, z_true: np.ndarray) -> dict:
    """{"truth_log_prob": the log posterior of the hidden truth on the run's calibration task,
    "truth_rank": the share of the kept samples whose log posterior is lower}. A rank near 1 says
    the chains missed the truth's region although it is as probable as any they visited (a mode
    the sampler did not find), not that the truth is implausible."""
    calibration, _ = _tasks(post.participant, post.trials, post.seed)
    value = float(log_probability(calibration)(z_true[None])[0])
    return {"truth_log_prob": value, "truth_rank": float(np.mean(post.log_prob < value))}


def _rms(v: np.ndarray) -> float:
    return float(np.sqrt(np.mean(np.square(v))))
