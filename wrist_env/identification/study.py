"""The Bayesian calibrator's study: a run per participant and seed (saved; a saved run is loaded), the
coverage table against the hidden truths and the figures."""

from __future__ import annotations

import numbers
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pandas as pd

from wrist_env import table2
from wrist_env.errors import StoreError
from wrist_env.figures.posterior import plot_intervals, plot_predictive
from wrist_env.identification.bayes import _tasks, calibrate
from wrist_env.identification.mcmc import log_probability
from wrist_env.identification.posterior import Posterior
from wrist_env.identification.settings import SamplerSettings
from wrist_env.limits import MAX_SEED, MAX_SEEDS, check_int
from wrist_env.participants import builtin
from wrist_env.task import task

LEVELS = (0.5, 0.9)


def study(
    participants,
    seeds,
    out,
    settings: SamplerSettings | None = None,
    *,
    progress: bool = True,
    on_run: Callable[[Posterior, bool], object] | None = None,
    report: str | Path | None = None,
    trials: str = "built-in",
):
    """A Bayesian calibration per participant and seed (`out/posterior_<P>_seed<s>.npz/.json`; a run
    already saved is loaded, not rerun), then the coverage table (one row per run: share of the 22 true
    z inside the 50 % and 90 % intervals, `against_truth`, recovery of the posterior mean, the MAP and the
    population design, diagnostics) as `out/coverage.csv` and the figures; returns the table.
    on_run(posterior, loaded) is called after each run; report: the folder of the table and figures
    (default `out`); a saved run sampled with other settings is an error; trials: "built-in" or "model"
    (`model_trials`; files and figures get a `_model` suffix); settings: the sampler and its settings
    (default `SamplerSettings()`, emcee; SMC's files get a `_smc` suffix). A saved run sampled on
    another model (`Posterior.model_hash`, the model's `source_hash`) is an error too. seeds: a count
    (seeds 0 .. seeds - 1, at most `MAX_SEEDS`) or the seeds themselves, checked before any run."""
    if isinstance(seeds, numbers.Integral):
        seeds = range(check_int("seeds", seeds, 1, MAX_SEEDS))
    seeds = [check_int("seed", seed, 0, MAX_SEED) for seed in seeds]
    out = Path(out)
    settings = SamplerSettings() if settings is None else settings
    sampler = settings.sampler
    suffix = ("" if trials == "built-in" else f"_{trials}") + ("" if sampler == "emcee" else f"_{sampler}")
    rows, posteriors = [], {}
    for participant in participants:
        truth = table2.z_scores(builtin.truth(participant)) if participant in builtin.BUILTIN else None
        for seed in seeds:
            path = out / f"posterior_{participant}_seed{seed}{suffix}.npz"
            loaded = path.exists()
            if loaded:
                post = _saved(path, participant, settings)
            else:
                post = calibrate(participant, seed, settings, progress=progress, trials=trials)
                post.save(path)
            if on_run is not None:
                on_run(post, loaded)
            posteriors.setdefault(participant, []).append(post)
            row = {
                "participant": participant,
                "trials": post.trials,
                "seed": seed,
                "sampler": post.sampler,
                **settings.record(),
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
                row.update(against_truth(post, truth))
                row["recovery_mean"] = _rms(post.mean - truth)
                row["recovery_map"] = _rms(post.map_z - truth)
                row["recovery_population"] = _rms(truth)
            rows.append(row)
    table = pd.DataFrame(rows)
    report = out if report is None else Path(report)
    report.mkdir(parents=True, exist_ok=True)
    table.to_csv(report / f"coverage{suffix}.csv", index=False)
    for participant, posts in posteriors.items():
        truth = table2.z_scores(builtin.truth(participant)) if participant in builtin.BUILTIN else None
        plot_intervals(posts, truth, report / f"posterior_intervals_{participant}{suffix}.png")
        plot_predictive(posts[0], report / f"posterior_predictive_{participant}{suffix}.png")
    return table


def _saved(path: Path, participant: str, settings: SamplerSettings) -> Posterior:
    """The run saved at `path`; a StoreError if it was sampled with other settings or on another model
    than today's (`Posterior.model_hash` against the model's `source_hash`)."""
    post = Posterior.load(path)
    model_hash = task(participant, "calibrate").model.source_hash  # cached: against_truth's task
    for what, saved, today in (
        ("with", post.settings, settings.record()),
        (f"on {participant}'s model", post.model_hash, model_hash),
    ):
        if saved is not None and saved != today:
            raise StoreError(
                f"{path} was sampled {what} {saved}, not today's {today}: delete it or choose another output folder"
            )
    return post


def against_truth(post: Posterior, z_true: np.ndarray) -> dict:
    """Where the hidden truth and the kept samples sit in the run's posterior (on its calibration task):
    truth_log_prob; truth_rank, the share of the kept samples whose log posterior is lower (near 1:
    a mode the chains did not find; near 0: the samples sit higher than the typical set);
    map_log_prob, the MAP's; mode_log_prob, the higher of the MAP's and the best sample's; truth_deficit and
    samples_deficit_median, the truth's and the samples' median log posterior below the mode
    (nats; for a calibrated Gaussian 22-dim posterior a draw sits χ²₂₂/2 below it, a median 10.7);
    mahalanobis2, the truth's squared Mahalanobis distance from the posterior mean in the samples'
    covariance (for a calibrated Gaussian posterior χ²₂₂, mean 22)."""
    calibration, _ = _tasks(post.participant, post.trials, post.seed)
    truth, at_map = (float(v) for v in log_probability(calibration)(np.stack([z_true, post.map_z])))
    mode = max(at_map, float(post.log_prob.max()))
    samples = post.samples.astype(float)
    offset = z_true - samples.mean(axis=0)
    return {
        "truth_log_prob": truth,
        "truth_rank": float(np.mean(post.log_prob < truth)),
        "map_log_prob": at_map,
        "mode_log_prob": mode,
        "truth_deficit": mode - truth,
        "samples_deficit_median": float(np.median(mode - post.log_prob)),
        "mahalanobis2": float(offset @ np.linalg.solve(np.cov(samples.T), offset)),
    }


def _rms(v: np.ndarray) -> float:
    return float(np.sqrt(np.mean(np.square(v))))
