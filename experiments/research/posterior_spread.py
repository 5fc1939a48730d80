"""Whether a saved posterior's narrow intervals are the chains' or the likelihood's.

For each saved run of the 1,200-step model-trial study (`leaderboards/posterior/steps1200/runs/`),
`study.against_truth`: the hidden truth's squared Mahalanobis distance from the posterior mean in the
kept samples' covariance (χ²₂₂ for a calibrated, near-Gaussian posterior: mean 22) and its χ²₂₂
quantile; how far the kept samples sit below the mode (the higher of the MAP's and the best
sample's log posterior; nats, median and 90th percentile; a calibrated Gaussian 22-dim posterior's
draws sit χ²₂₂/2 below it, a median 10.7); the truth's own deficit, its χ²₂₂/2 quantile, and its
rank among the samples; how far the MAP sits above the best sample. Prints a table; writes nothing.

Run: `python experiments/research/posterior_spread.py [folder]` (~40 s for the nine runs: two simulations a run).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pandas as pd
from scipy.stats import chi2

from wrist_env import design, table2
from wrist_env.identification.posterior import Posterior
from wrist_env.identification.study import against_truth
from wrist_env.participants import builtin

RUNS = Path(__file__).resolve().parents[2] / "leaderboards/posterior/steps1200/runs"


def spread(post: Posterior) -> dict:
    """One run's row: `against_truth` with the χ²₂₂ quantiles and the samples' 90th-percentile deficit."""
    dim = post.samples.shape[1]
    at = against_truth(post, table2.z_scores(builtin.truth(post.participant)))
    return {
        "participant": post.participant,
        "seed": post.seed,
        "mahalanobis2": round(at["mahalanobis2"], 1),
        "chi2_quantile": round(float(chi2.cdf(at["mahalanobis2"], dim)), 3),
        "samples_deficit_median": round(at["samples_deficit_median"], 1),
        "samples_deficit_p90": round(float(np.percentile(at["mode_log_prob"] - post.log_prob, 90)), 1),
        "truth_deficit": round(at["truth_deficit"], 1),
        "truth_deficit_quantile": round(float(chi2.cdf(2 * at["truth_deficit"], dim)), 3),
        "truth_rank": round(at["truth_rank"], 3),
        "map_above_best_sample": round(at["map_log_prob"] - float(post.log_prob.max()), 1),
    }


def main(folder: Path = RUNS) -> pd.DataFrame:
    dim = design.N_MATERIAL
    print(f"a calibrated Gaussian {dim}-dim posterior: draws a median {chi2.ppf(0.5, dim) / 2:.1f} nats below the mode")
    table = pd.DataFrame([spread(Posterior.load(path)) for path in sorted(folder.glob("posterior_*_model.npz"))])
    print(table.to_string(index=False))
    return table


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else RUNS)
