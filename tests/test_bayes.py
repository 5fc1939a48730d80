"""The Bayesian calibrator (`wrist_env.bayes`): the sampler against a closed-form posterior, its
diagnostics, and a short run on P1 through the command."""

import json

import numpy as np
import pytest

from wrist_env import bayes, design
from wrist_env.cli import main


def test_the_sampler_recovers_a_linear_gaussian_posterior():
    """y = A z + ε, ε ~ N(0, 0.5²), prior N(0, I) in 4 dimensions: the posterior is N(m, C) with
    C = (AᵀA / 0.25 + I)⁻¹, m = C Aᵀ y / 0.25. The sampled mean is within 0.1 posterior SD of m and
    each SD within 10 % of √diag C; R̂ < 1.05."""
    rng = np.random.default_rng(1)
    A = rng.normal(size=(12, 4)) * np.array([3.0, 1.0, 0.3, 0.05])  # from well to hardly identified
    y = A @ rng.normal(size=4) + rng.normal(0, 0.5, 12)
    C = np.linalg.inv(A.T @ A / 0.25 + np.eye(4))
    m = C @ A.T @ y / 0.25

    def log_prob(Z):
        return -0.5 * np.sum((y - Z @ A.T) ** 2, axis=1) / 0.25 - 0.5 * np.sum(Z**2, axis=1)

    out = bayes.sample(log_prob, rng.normal(size=(32, 4)), 4000, seed=0)
    samples = out["chain"].reshape(-1, 4)
    sd = np.sqrt(np.diag(C))
    assert np.all(np.abs(samples.mean(axis=0) - m) < 0.1 * sd), (samples.mean(axis=0) - m) / sd
    np.testing.assert_allclose(samples.std(axis=0), sd, rtol=0.1)
    assert np.all(out["rhat"] < 1.05) and np.all(out["ess"] > 500)


def test_split_rhat_flags_chains_that_disagree():
    rng = np.random.default_rng(0)
    mixed = rng.normal(size=(500, 8, 2))
    stuck = mixed + np.array([0.0, 2.0])[None, None, :] * (np.arange(8) % 2)[None, :, None]
    assert np.all(bayes.split_rhat(mixed) < 1.02)
    r = bayes.split_rhat(stuck)
    assert r[0] < 1.02 and r[1] > 1.3


@pytest.mark.slow
def test_the_command_samples_p1_and_writes_coverage_and_figures(built, tmp_path, capsys):
    """`wrist-bench posterior P1` with a short chain: a saved posterior per seed, coverage in [0, 1],
    the intervals and predictive figures; rerun, it loads instead of sampling."""
    built("P1")
    args = ["posterior", "P1", "--seeds", "1", "--walkers", "48", "--steps", "8", "--out", str(tmp_path)]
    assert main(args) == 0
    import pandas as pd

    table = pd.read_csv(tmp_path / "coverage.csv")
    assert len(table) == 1 and table.coverage_90.between(0, 1).all() and table.coverage_90[0] >= table.coverage_50[0]
    assert (tmp_path / "posterior_intervals_P1.png").stat().st_size > 10_000
    assert (tmp_path / "posterior_predictive_P1.png").stat().st_size > 10_000
    post = bayes.Posterior.load(tmp_path / "posterior_P1_seed0.npz")
    assert post.samples.shape == (4 * 48, design.N_MATERIAL) and post.predictive.shape[:3] == (2, 3, 2)
    assert json.loads((tmp_path / "posterior_P1_seed0.json").read_text())["evaluations"] == post.evaluations
    capsys.readouterr()
    assert main(args) == 0
    assert "loaded" in capsys.readouterr().out


def test_the_laplace_covariance_takes_the_noise_the_fit_implies():
    """Residual rows alternate 3 translations, 3 rotations; with translation residuals of RMS 2 their
    Jacobian rows count a quarter: (J_tᵀJ_t / 4 + J_rᵀJ_r + I)⁻¹."""
    rng = np.random.default_rng(0)
    J = rng.normal(size=(60, 5))
    translation = np.arange(60) % 6 < 3
    r = np.where(translation, 2.0, 1.0) * rng.choice([-1.0, 1.0], 60)
    expected = np.linalg.inv(J[translation].T @ J[translation] / 4 + J[~translation].T @ J[~translation] + np.eye(5))
    np.testing.assert_allclose(bayes.laplace_covariance(r, J), expected, rtol=1e-12)
