"""Whether a saved posterior's narrow intervals are the chains' or the likelihood's.

For each saved run of the 1,200-step model-trial study (`leaderboards/posterior/steps1200/runs/`):
the hidden truth's squared Mahalanobis distance from the posterior mean in the kept samples'
covariance (χ²₂₂ for a calibrated, near-Gaussian posterior: mean 22), how far the kept samples
sit below the best of them (nats, median and 90th percentile; a regular 22-dimensional
posterior's draws sit χ²₂₂/2 below the mode, a median 10.7), and the truth's own deficit and rank
(`study.truth_rank`). Prints a table; writes nothing.

Run: `python experiments/research/posterior_spread.py [folder]` (~10 s for the five runs so far: one simulation of the truth a run).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pandas as pd
from scipy.stats import chi2

from wrist_env import design
from wrist_env.identification.posterior import Posterior
from wrist_env.identification.study import truth_rank
from wrist_env.participants import builtin

RUNS = Path(__file__).resolve().parents[2] / "leaderboards/posterior/steps1200/runs"


def spread(post: Posterior) -> dict:
    """The truth's Mahalanobis², the samples' and the truth's deficits below the best sample (nats)."""
    truth = design.z_scores(builtin.truth(post.participant))
    samples = post.samples.astype(float)
    offset = truth - samples.mean(axis=0)
    mahalanobis2 = float(offset @ np.linalg.solve(np.cov(samples.T), offset))
    deficit = post.log_prob.max() - post.log_prob
    rank = truth_rank(post, truth)
    return {
        "participant": post.participant,
        "seed": post.seed,
        "mahalanobis2": round(mahalanobis2, 1),
        "chi2_quantile": round(float(chi2.cdf(mahalanobis2, samples.shape[1])), 3),
        "samples_deficit_median": round(float(np.median(deficit)), 1),
        "samples_deficit_p90": round(float(np.percentile(deficit, 90)), 1),
        "truth_deficit": round(float(post.log_prob.max() - rank["truth_log_prob"]), 1),
        "truth_rank": round(rank["truth_rank"], 3),
    }


def main(folder: Path = RUNS) -> pd.DataFrame:
    dim = design.N_MATERIAL
    print(f"a calibrated {dim}-dim posterior: draws a median {chi2.ppf(0.5, dim) / 2:.1f} nats below the mode")
    table = pd.DataFrame([spread(Posterior.load(path)) for path in sorted(folder.glob("posterior_*_model.npz"))])
    print(table.to_string(index=False))
    return table


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else RUNS)
