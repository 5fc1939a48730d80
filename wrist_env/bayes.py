"""A Bayesian calibrator: the posterior of the 22 materials given a participant's calibration trial.

Target: `posterior.log_likelihood` of the per-frame scaphoid and lunate DOF residuals (noise scales
of translations and rotations integrated out) + `posterior.log_prior` (Table 2, z units, |z| ≤ 3).

Sampler: emcee's ensemble MCMC (Foreman-Mackey et al. 2013, PASP 125:306), chosen because its
ensemble is a batch: every step moves all walkers at once, so one step is one batched solver call
(`vectorize=True`), the way the solver is fast; it is pure NumPy. Its moves are differential
evolution (80 %) and DE snooker (20 %) (ter Braak & Vrugt 2008, Stat Comput 18:435), which mix
better than the default stretch move in 22 dimensions. Gradient samplers (NUTS) need derivatives
the explicit solver does not give; nested sampling (dynesty) and flow-preconditioned SMC (pocomc,
which needs torch) spend more simulations or dependencies on one posterior.

Start: the walkers are drawn around the MAP (`map_estimate`: the best of several trust-region Gauss–Newton
runs on the residuals at the 4DCT noise and the prior) from its Laplace covariance
(`laplace_covariance`); the first half of the steps is burn-in and discarded.

Diagnostics (`Posterior`): the integrated autocorrelation time τ of each material (emcee), the
effective sample size (kept samples / τ), split R̂ over the walkers (Gelman et al., BDA3 §11.4;
the stricter of the two on short chains) and the acceptance rate. Predictive bands: `PREDICTIVE_DRAWS` posterior draws simulated on the
calibration and the held-out trial, 5/50/95 % of each DOF at each frame.
"""

from __future__ import annotations

import json
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from wrist_env import design, posterior
from wrist_env.envs.task import Task, cost_poses, task
from wrist_env.frames import pose_to_dof

WALKERS = 48
STEPS = 1200
"""Ensemble steps: at 300 the chains were overconfident even on the model's own trials (README); ~12 min a run."""
MAP_STARTS = 8
FD_STEP_Z = 0.1
"""Forward-difference step of the MAP search's Jacobian (SD units)."""
FAILED_RESIDUAL = 30.0
"""Residual (noise units) of every DOF of a failed run in the MAP search."""
PREDICTIVE_DRAWS = 32
QUANTILES = (0.05, 0.25, 0.5, 0.75, 0.95)


@dataclass(frozen=True)
class Posterior:
    """Posterior samples of the 22 materials (z units) and their diagnostics.

    samples (n, 22): the kept chain, walkers and steps flattened; log_prob (n,).
    map_z (22,): the start (MAP at the 4DCT noise); autocorr (22,): τ in steps; ess (22,): kept
    samples / τ (τ from a chain shorter than 50 τ is low, so this is then an upper bound);
    rhat (22,): split R̂ over walkers; acceptance: mean acceptance rate; noise (2,): posterior median
    of the translation (mm) and rotation (deg) noise scale; evaluations: simulations run.
    predictive (2 motions, 3 quantiles 5/50/95 %, 2 bones, n_frames, 6) DOF (mm, deg) of the
    calibration and held-out trial; observed (2, 2, n_frames, 6) the trials' own DOF.
    trials: "built-in" (the participant's trials) or "model" (`model_trials`: no model error).
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
        """`<path>.npz` (arrays) and `<path>.json` (scalars and the summary)."""
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        arrays = {k: getattr(self, k) for k in self.ARRAYS}
        arrays["samples"] = arrays["samples"].astype(np.float32)  # 1e-7 SD: plenty, half the file
        np.savez_compressed(path.with_suffix(".npz"), **arrays)
        scalars = {k: v for k, v in asdict(self).items() if k not in self.ARRAYS}
        scalars["materials"] = list(design.NAMES[: design.N_MATERIAL])
        path.with_suffix(".json").write_text(json.dumps(scalars, indent=1) + "\n")
        return path.with_suffix(".npz")

    @classmethod
    def load(cls, path: str | Path) -> Posterior:
        path = Path(path)
        scalars = json.loads(path.with_suffix(".json").read_text())
        scalars.pop("materials", None)
        with np.load(path.with_suffix(".npz")) as data:
            arrays = {k: data[k] for k in cls.ARRAYS}
        return cls(**scalars, **arrays)


def map_estimate(
    calibration: Task, starts: int = MAP_STARTS, seed: int = 0, max_evaluations: int = 40
) -> tuple[np.ndarray, np.ndarray, np.ndarray, int]:
    """(MAP z (22,), its residuals (n,), their Jacobian (n, 22), simulations run): the best of
    trust-region Gauss–Newton runs (SciPy's `least_squares`, TRF, |z| ≤ 3) on [residuals; z] from the
    population design and `starts` − 1 draws of N(0, 0.7²) (the misfit is multimodal: on P1, 1 of 6
    random starts reached the basin of the hidden truth)."""
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


def log_probability(calibration: Task, counter: list | None = None) -> Callable[[np.ndarray], np.ndarray]:
    """The batched log posterior (W, 22) → (W,) of z on the calibration trial."""
    base = design.population()

    def log_prob(Z):
        Z = np.atleast_2d(Z)
        out = posterior.log_prior(Z)
        inside = np.flatnonzero(np.isfinite(out))
        if len(inside):
            evaluations = calibration.evaluate_batch([design.with_z(base, Z[k]) for k in inside])
            if counter is not None:
                counter[0] += len(inside)
            for k, e in zip(inside, evaluations):
                ok = not e.failed
                out[k] += posterior.log_likelihood(posterior.residuals(calibration, e.result.poses)) if ok else -np.inf
        return out

    return log_prob


def sample(log_prob, start: np.ndarray, steps: int, seed: int, progress: bool = False) -> dict:
    """Run emcee from `start` (walkers, dim) for `steps`; the second half kept.

    Returns {"chain": (kept, walkers, dim), "log_prob": (kept, walkers), "acceptance",
    "autocorr" (dim,), "ess" (dim,), "rhat" (dim,)}.
    """
    import logging

    import emcee

    logging.getLogger("emcee").setLevel(logging.ERROR)  # a short chain's τ is reported, not warned about
    walkers, dim = start.shape
    moves = [(emcee.moves.DEMove(), 0.8), (emcee.moves.DESnookerMove(), 0.2)]
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


def split_rhat(chain: np.ndarray) -> np.ndarray:
    """Split R̂ (dim,) of a chain (steps, chains, dim): each chain's halves as two chains (BDA3 §11.4)."""
    n = chain.shape[0] // 2
    halves = np.concatenate([chain[:n], chain[n : 2 * n]], axis=1)  # (n, 2·chains, dim)
    within = halves.var(axis=0, ddof=1).mean(axis=0)
    between = n * halves.mean(axis=0).var(axis=0, ddof=1)
    return np.sqrt(((n - 1) / n * within + between / n) / within)


TRIALS = ("built-in", "model")


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
    rng = np.random.default_rng([seed, ("calibrate", "validate").index(t.motion)])
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
) -> Posterior:
    """Sample the posterior of `participant`'s 22 materials given its calibration trial (see the module doc);
    trials="model" calibrates against `model_trials` instead."""
    start_time = time.perf_counter()
    calibration, held_out = _tasks(participant, trials, seed)
    map_z, r, J, runs = map_estimate(calibration, seed=seed)
    rng = np.random.default_rng(seed)
    start = rng.multivariate_normal(map_z, laplace_covariance(r, J), size=walkers)
    start = np.clip(start, -0.99 * posterior.BOUND_Z, 0.99 * posterior.BOUND_Z)
    counter = [runs]
    out = sample(log_probability(calibration, counter), start, steps, seed, progress)
    samples = out["chain"].reshape(-1, design.N_MATERIAL)
    draws = samples[rng.choice(len(samples), PREDICTIVE_DRAWS, replace=False)]
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
        out["log_prob"].ravel(),
        map_z,
        out["autocorr"],
        out["ess"],
        out["rhat"],
        out["acceptance"],
        noise,
        counter[0],
        time.perf_counter() - start_time,
        np.stack(predictive),
        np.stack(observed),
        trials,
    )


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
):
    """A Bayesian calibration per participant and seed (`out/posterior_<P>_seed<s>.npz/.json`; a run
    already saved is loaded, not rerun), then the coverage table (one row per run: share of the 22 true
    z inside the 50 % and 90 % intervals, `truth_rank`, recovery of the posterior mean, the MAP and the
    population design, diagnostics) as `out/coverage.csv` and the figures; returns the table.
    on_run(posterior, loaded) is called after each run; report: the folder of the table and figures
    (default `out`); trials: "built-in" or "model" (`model_trials`; files and figures get a `_model`
    suffix)."""
    import pandas as pd

    from wrist_env.figures.posterior import plot_intervals, plot_predictive
    from wrist_env.participants import builtin

    out = Path(out)
    suffix = "" if trials == "built-in" else f"_{trials}"
    rows, posteriors = [], {}
    for participant in participants:
        truth = design.z_scores(builtin.truth(participant)) if participant in builtin.BUILTIN else None
        for seed in range(seeds) if isinstance(seeds, int) else seeds:
            path = out / f"posterior_{participant}_seed{seed}{suffix}.npz"
            loaded = path.exists()
            if loaded:
                post = Posterior.load(path)
            else:
                post = calibrate(participant, seed, walkers, steps, progress, trials)
                post.save(path)
            if on_run is not None:
                on_run(post, loaded)
            posteriors.setdefault(participant, []).append(post)
            row = {
                "participant": participant,
                "trials": post.trials,
                "seed": seed,
                "walkers": walkers,
                "steps": steps,
                "evaluations": post.evaluations,
                "wall_seconds": round(post.wall_seconds, 1),
                "acceptance": post.acceptance,
                "ess_min": float(np.nanmin(post.ess)),
                "rhat_max": float(np.nanmax(post.rhat)),
                "noise_mm": post.noise[0],
                "noise_deg": post.noise[1],
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
