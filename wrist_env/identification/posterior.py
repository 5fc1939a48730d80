"""A posterior sample of the 22 materials and its diagnostics, saved as `.npz` + JSON."""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from wrist_env.io import load_dataclass, save_dataclass

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
    settings: the sampler's settings (`SamplerSettings.record`); None in files saved before they were recorded.
    model_hash: the calibration model's `Model.source_hash`; None in files saved before it was recorded.
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
    model_hash: str | None = None

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
