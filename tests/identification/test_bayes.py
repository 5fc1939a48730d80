"""The Bayesian calibrator (`wrist_env.identification`): the sampler against a closed-form posterior, its
diagnostics, and a short run on P1 through the command."""

import dataclasses
import json
import warnings

import numpy as np
import pytest

from wrist_env import design
from wrist_env.cli import main
from wrist_env.errors import InputError
from wrist_env.identification import bayes, mcmc, posterior, smc
from wrist_env.identification import map as map_
from wrist_env.identification import study as study_
from wrist_env.identification.settings import (
    MAP_STARTS,
    MCMC_STEPS,
    MIN_STEPS,
    PRIOR_REFRESH,
    STEPS,
    SamplerSettings,
)
from wrist_env.participants.registry import load_model


def _linear_gaussian():
    """y = A z + ε, ε ~ N(0, 0.5²), prior N(0, I) in 4 dimensions: the posterior is N(m, C) with
    C = (AᵀA / 0.25 + I)⁻¹, m = C Aᵀ y / 0.25, and with the likelihood's normaliser left out the
    evidence is log ∫ L(z) N(z; 0, I) dz = ½ log det C − ½ (Σ y² / 0.25 − mᵀ C⁻¹ m).
    Returns (log likelihood, m, C, log evidence)."""
    rng = np.random.default_rng(1)
    A = rng.normal(size=(12, 4)) * np.array([3.0, 1.0, 0.3, 0.05])  # from well to hardly identified
    y = A @ rng.normal(size=4) + rng.normal(0, 0.5, 12)
    C = np.linalg.inv(A.T @ A / 0.25 + np.eye(4))

    def log_like(Z):
        return -0.5 * np.sum((y - Z @ A.T) ** 2, axis=1) / 0.25

    m = C @ A.T @ y / 0.25
    log_evidence = 0.5 * np.linalg.slogdet(C)[1] - 0.5 * (y @ y / 0.25 - m @ np.linalg.solve(C, m))
    return log_like, m, C, log_evidence


def test_the_sampler_recovers_a_linear_gaussian_posterior():
    """emcee on the closed-form posterior: the sampled mean is within 0.1 posterior SD of m and each
    SD within 10 % of √diag C; R̂ < 1.05."""
    log_like, m, C, _ = _linear_gaussian()
    out = mcmc.sample(
        lambda Z: log_like(Z) - 0.5 * np.sum(Z**2, axis=1), np.random.default_rng(0).normal(size=(32, 4)), 4000, seed=0
    )
    samples = out["chain"].reshape(-1, 4)
    sd = np.sqrt(np.diag(C))
    assert np.all(np.abs(samples.mean(axis=0) - m) < 0.1 * sd), (samples.mean(axis=0) - m) / sd
    np.testing.assert_allclose(samples.std(axis=0), sd, rtol=0.1)
    assert np.all(out["rhat"] < 1.05) and np.all(out["ess"] > 500)


def test_smc_recovers_a_linear_gaussian_posterior_and_its_evidence():
    """SMC from the prior (truncated at |z| ≤ 3, which holds 99.7 % of each N(0, 1)) on the same
    posterior: mean within 0.15 posterior SD, SDs within 15 %, log evidence within 0.3 of the closed form."""
    log_like, m, C, log_evidence = _linear_gaussian()
    out = smc.sample_smc(log_like, 4, particles=2000, mcmc_steps=10, seed=0)
    sd = np.sqrt(np.diag(C))
    samples = out["samples"]
    assert samples.shape == (2000, 4) and out["phi"][0] == 0 and out["phi"][-1] == 1
    assert np.all(np.abs(samples.mean(axis=0) - m) < 0.15 * sd), (samples.mean(axis=0) - m) / sd
    np.testing.assert_allclose(samples.std(axis=0), sd, rtol=0.15)
    np.testing.assert_allclose(out["log_likelihood"], log_like(samples))
    assert abs(out["log_evidence"] - log_evidence) < 0.3, (out["log_evidence"], log_evidence)
    assert np.all((out["acceptance"] > 0) & (out["acceptance"] <= 1))


def test_emcee_with_the_prior_refresh_keeps_a_hinges_exact_marginal():
    """A hinge, as a reference strain makes a ligament slack: the likelihood of z₀ is flat up to 0.5
    and falls off a cliff beyond, z₁ is well identified; walkers start in a tight ball at the hinge
    (as from a MAP where the ligament just engages). z₀'s sampled 5/50/95 % quantiles match the exact
    marginal (the prior truncated by the cliff, by quadrature) within 0.1 SD."""
    from scipy.stats import norm

    def log_prob(Z):
        cliff = -50.0 * np.clip(Z[:, 0] - 0.5, 0.0, None) ** 2
        inside = np.all(np.abs(Z) <= 3, axis=1)
        value = cliff - 0.5 * ((Z[:, 1] - 1.0) / 0.1) ** 2 - 0.5 * np.sum(Z**2, axis=1)
        return np.where(inside, value, -np.inf)

    start = np.array([0.5, 1.0]) + 0.01 * np.random.default_rng(0).normal(size=(32, 2))
    samples = mcmc.sample(log_prob, start, 3000, seed=0)["chain"].reshape(-1, 2)
    x = np.linspace(-3, 3, 60_001)
    density = norm.pdf(x) * np.exp(-50.0 * np.clip(x - 0.5, 0.0, None) ** 2)
    cdf = np.cumsum(density) / density.sum()
    exact = np.interp([0.05, 0.5, 0.95], cdf, x)
    np.testing.assert_allclose(np.quantile(samples[:, 0], [0.05, 0.5, 0.95]), exact, atol=0.1)


def test_split_rhat_flags_chains_that_disagree():
    rng = np.random.default_rng(0)
    mixed = rng.normal(size=(500, 8, 2))
    stuck = mixed + np.array([0.0, 2.0])[None, None, :] * (np.arange(8) % 2)[None, :, None]
    assert np.all(mcmc.split_rhat(mixed) < 1.02)
    r = mcmc.split_rhat(stuck)
    assert r[0] < 1.02 and r[1] > 1.3


@pytest.mark.slow
def test_the_command_samples_p1_and_writes_coverage_and_figures(built, tmp_path, capsys):
    """`wrist-bench posterior P1` with a short chain: a saved posterior per seed, coverage in [0, 1],
    the intervals and predictive figures; rerun, it loads instead of sampling."""
    built("P1")
    args = ["posterior", "P1", "--seeds", "1", "--walkers", "48", "--steps", "8", "--map-starts", "1"]
    args += ["--out", str(tmp_path)]
    assert main(args) == 0
    import pandas as pd

    table = pd.read_csv(tmp_path / "coverage.csv")
    assert len(table) == 1 and table.coverage_90.between(0, 1).all() and table.coverage_90[0] >= table.coverage_50[0]
    assert (tmp_path / "posterior_intervals_P1.png").stat().st_size > 10_000
    assert (tmp_path / "posterior_predictive_P1.png").stat().st_size > 10_000
    post = posterior.Posterior.load(tmp_path / "posterior_P1_seed0.npz")
    assert post.samples.shape == (4 * 48, design.N_MATERIAL) and post.predictive.shape[:3] == (2, 3, 2)
    assert json.loads((tmp_path / "posterior_P1_seed0.json").read_text())["fields"]["evaluations"] == post.evaluations
    assert post.settings == {"walkers": 48, "steps": 8, "map_starts": 1, "prior_refresh": PRIOR_REFRESH}
    capsys.readouterr()
    assert main(args) == 0
    assert "loaded" in capsys.readouterr().out
    assert main([*args, "--prior-refresh", "0"]) == 2  # a saved run is not taken for one with other settings
    assert "posterior_P1_seed0.npz was sampled with" in capsys.readouterr().err
    # nor for a run on another model: the saved run names the model it was sampled on
    saved = tmp_path / "posterior_P1_seed0.json"
    record = json.loads(saved.read_text())
    assert record["fields"]["model_hash"] == load_model("P1").source_hash
    record["fields"]["model_hash"] = "0123456789abcdef"
    saved.write_text(json.dumps(record))
    assert main(args) == 2
    assert "posterior_P1_seed0.npz was sampled on P1's model 0123456789abcdef, not today's" in capsys.readouterr().err


def test_smc_from_a_defensive_start_off_the_mode_recovers_the_same_posterior():
    """The geometric bridge from a `DefensiveStart` centred 1 posterior SD off the mean, with half the
    covariance: the same closed-form posterior and evidence as from the prior."""
    log_like, m, C, log_evidence = _linear_gaussian()
    sd = np.sqrt(np.diag(C))
    out = smc.sample_smc(log_like, 4, 2000, 10, seed=0, start=smc.DefensiveStart(m + sd, 0.5 * C))
    samples = out["samples"]
    assert np.all(np.abs(samples.mean(axis=0) - m) < 0.15 * sd), (samples.mean(axis=0) - m) / sd
    np.testing.assert_allclose(samples.std(axis=0), sd, rtol=0.15)
    assert abs(out["log_evidence"] - log_evidence) < 0.3, (out["log_evidence"], log_evidence)


def test_the_defensive_start_is_a_normalized_density_on_the_prior_box():
    """Its density integrates to 1 over |z| ≤ 3 (a 2-D grid; the t is centred near the edge, so its
    truncation matters), its draws stay in the box, and 20 % of them follow the prior."""
    start = smc.DefensiveStart(np.array([2.5, -1.0]), np.array([[0.3, 0.1], [0.1, 0.2]]))
    g = np.linspace(-3, 3, 601)
    grid = np.stack(np.meshgrid(g, g), axis=-1).reshape(-1, 2)
    assert np.exp(start.logpdf(grid)).sum() * (g[1] - g[0]) ** 2 == pytest.approx(1.0, abs=0.01)
    assert start.logpdf(np.array([[3.1, 0.0]]))[0] == -np.inf
    draws = start.rvs(100_000, random_state=1)
    assert draws.shape == (100_000, 2) and np.all(np.abs(draws) <= 3)
    # the t puts almost nothing below z₀ = −2 (its centre 2.5, SD ≈ 0.8); the prior puts 2.15 % there
    assert np.mean(draws[:, 0] < -2) == pytest.approx(smc.PRIOR_SHARE * 0.02146, abs=0.0008)


@pytest.mark.slow
def test_the_command_runs_smc_and_keeps_its_own_files(built, tmp_path, capsys):
    """`wrist-bench posterior P1 --sampler smc` with few particles: an `_smc` posterior of `particles`
    samples that all satisfy the prior box, each with its own log posterior, stages and evidence in
    its JSON, an `_smc` table."""
    built("P1")
    args = ["posterior", "P1", "--sampler", "smc", "--particles", "44", "--mcmc-steps", "1", "--map-starts", "1"]
    args += ["--out", str(tmp_path)]
    assert main(args) == 0
    post = posterior.Posterior.load(tmp_path / "posterior_P1_seed0_smc.npz")
    assert post.sampler == "smc" and post.samples.shape == (44, design.N_MATERIAL)
    assert np.all(np.abs(post.samples) <= 3) and post.stages >= 1 and np.isfinite(post.log_evidence)
    assert post.evaluations >= 44 * (post.stages + 1) and np.all(np.isnan(post.rhat))
    # the stored log posterior is the particle's own (prior included); within 1 nat, as the samples are
    # stored in float32 and the solver's stopping rule makes the likelihood rough at that scale
    best = post.samples[np.argmax(post.log_prob)]
    assert post.log_prob.max() == pytest.approx(
        float(mcmc.log_probability(bayes._tasks("P1", "built-in", 0)[0])(best[None])[0]), abs=1.0
    )
    import pandas as pd

    table = pd.read_csv(tmp_path / "coverage_smc.csv")
    assert table.sampler.tolist() == ["smc"] and table.particles.tolist() == [44] and table.stages[0] == post.stages
    assert "distinct particles" in capsys.readouterr().out


def test_the_laplace_covariance_takes_the_noise_the_fit_implies():
    """Residual rows alternate 3 translations, 3 rotations; with translation residuals of RMS 2 their
    Jacobian rows count a quarter: (J_tᵀJ_t / 4 + J_rᵀJ_r + I)⁻¹."""
    rng = np.random.default_rng(0)
    J = rng.normal(size=(60, 5))
    translation = np.arange(60) % 6 < 3
    r = np.where(translation, 2.0, 1.0) * rng.choice([-1.0, 1.0], 60)
    expected = np.linalg.inv(J[translation].T @ J[translation] / 4 + J[~translation].T @ J[~translation] + np.eye(5))
    np.testing.assert_allclose(map_.laplace_covariance(r, J), expected, rtol=1e-12)


def test_model_trials_carry_the_tracking_noise_and_no_model_error(built):
    """The model's own run of the hidden truth plus tracking noise: at the truth the residuals are the
    noise alone (0.2 mm and 0.5° RMS rigid, so ~0.12 mm and ~0.29° per DOF at the centroid: about 0.6
    noise units each), below the built-in trial's (noise plus the fidelity gap); the noise follows the
    seed, the held-out trial gets its own draw, and a participant without a truth is refused."""
    from wrist_env.identification import likelihood
    from wrist_env.participants import builtin
    from wrist_env.task import task

    built("P1")
    trial = task("P1", "calibrate")
    model = bayes.model_trials(trial, seed=0)
    truth = builtin.truth("P1")
    r_model = likelihood.residuals(model, trial.evaluate(truth).result.poses)
    r_trial = likelihood.residuals(trial, trial.evaluate(truth).result.poses)
    rms = np.sqrt(np.mean(r_model[..., :3] ** 2)), np.sqrt(np.mean(r_model[..., 3:] ** 2))
    assert 0.4 < rms[0] < 0.85 and 0.4 < rms[1] < 0.85, rms
    assert np.sum(r_model**2) < 0.6 * np.sum(r_trial**2)
    np.testing.assert_array_equal(bayes.model_trials(trial, seed=0).reference, model.reference)
    assert not np.allclose(bayes.model_trials(trial, seed=1).reference, model.reference)
    assert trial.reference is not model.reference and model.driver is trial.driver
    with pytest.raises(ValueError, match="trials must be one of"):
        bayes.calibrate("P1", trials="simulated")


def test_tracking_noise_has_the_stated_rms():
    """0.2 mm and 0.5° RMS: the centroid's displacement and the rotation angle over 20,000 frames."""
    from scipy.spatial.transform import Rotation

    from wrist_env.participants import builtin

    rng = np.random.default_rng(0)
    poses = np.tile(np.eye(4), (20_000, 1, 1))
    poses[:, :3, :3] = Rotation.random(20_000, random_state=1).as_matrix()
    centroid = np.array([10.0, -5.0, 30.0])
    noisy = builtin.tracking_noise(poses, centroid, rng)
    moved = np.einsum("fij,j->fi", poses[:, :3, :3], centroid) + poses[:, :3, 3]
    moved_noisy = np.einsum("fij,j->fi", noisy[:, :3, :3], centroid) + noisy[:, :3, 3]
    shift = np.sqrt(np.mean(np.sum((moved_noisy - moved) ** 2, axis=1)))
    turn = Rotation.from_matrix(noisy[:, :3, :3] @ np.transpose(poses[:, :3, :3], (0, 2, 1))).magnitude()
    assert shift == pytest.approx(builtin.TRACKING_NOISE_MM, rel=0.03)
    assert np.degrees(np.sqrt(np.mean(turn**2))) == pytest.approx(builtin.TRACKING_NOISE_DEG, rel=0.03)


def test_a_model_trials_study_keeps_its_own_files_and_says_so(built, tmp_path, monkeypatch):
    """The study with trials="model" saves `_model` files and table, marks its rows, and passes the
    choice to the calibrator (here a stand-in that returns a fixed posterior, to test the bookkeeping)."""
    built("P1")
    asked = []
    n_frames = 15

    def fake(participant, seed, settings, progress, trials):
        asked.append(trials)
        rng = np.random.default_rng(seed)
        zeros = np.zeros(design.N_MATERIAL)
        return posterior.Posterior(
            participant, seed, rng.normal(size=(96, design.N_MATERIAL)), np.zeros(96), zeros, zeros + 1,
            zeros + 96, zeros + 1, 0.3, np.array([0.1, 0.3]), 10, 1.0,
            np.zeros((2, 3, 2, n_frames, 6)), np.zeros((2, 2, n_frames, 6)), trials,
        )  # fmt: skip

    monkeypatch.setattr(study_, "calibrate", fake)
    table = study_.study(["P1"], 2, tmp_path, progress=False, trials="model")
    assert asked == ["model", "model"] and (table.trials == "model").all()
    # the stand-in's samples all have log posterior 0, above any real design's: the truth ranks 0
    assert (
        np.isfinite(table.truth_log_prob).all() and (table.truth_log_prob < 0).all() and (table.truth_rank == 0).all()
    )
    assert (table.mode_log_prob == 0).all() and (table.samples_deficit_median == 0).all()
    assert np.allclose(table.truth_deficit, -table.truth_log_prob) and np.isfinite(table.mahalanobis2).all()
    assert (tmp_path / "coverage_model.csv").exists() and not (tmp_path / "coverage.csv").exists()
    assert posterior.Posterior.load(tmp_path / "posterior_P1_seed1_model.npz").trials == "model"
    assert (tmp_path / "posterior_intervals_P1_model.png").exists()


def test_against_truth_places_the_truth_in_a_gaussian_posterior_as_closed_form_says(monkeypatch):
    """With a standard-normal log posterior in 22 dimensions and 40,000 draws from it: the draws sit
    a median χ²₂₂/2 below the mode (scipy's quantile), the truth ½|t|² below it, and its squared
    Mahalanobis distance is |t|²."""
    from scipy.stats import chi2

    rng = np.random.default_rng(3)
    dim = design.N_MATERIAL
    draws = rng.normal(size=(40_000, dim))
    truth = np.linspace(-1.5, 1.5, dim)
    monkeypatch.setattr(study_, "_tasks", lambda *args: (None, None))
    monkeypatch.setattr(study_, "log_probability", lambda calibration: lambda Z: -0.5 * np.sum(Z**2, axis=1))
    zeros = np.zeros(dim)
    post = posterior.Posterior(
        "P1", 0, draws, -0.5 * np.sum(draws**2, axis=1), zeros, zeros + 1, zeros + 400, zeros + 1, 0.3,
        np.array([0.1, 0.3]), 40_000, 1.0, np.zeros((2, 3, 2, 4, 6)), np.zeros((2, 2, 4, 6)), "model",
    )  # fmt: skip
    at = study_.against_truth(post, truth)
    assert at["mode_log_prob"] == 0.0  # the MAP (zeros) is above every draw
    assert at["samples_deficit_median"] == pytest.approx(chi2.ppf(0.5, dim) / 2, abs=0.1)
    assert at["truth_deficit"] == pytest.approx(0.5 * truth @ truth)
    assert at["mahalanobis2"] == pytest.approx(truth @ truth, rel=0.03)
    assert at["truth_rank"] == pytest.approx(chi2.sf(truth @ truth, dim), abs=0.01)


@pytest.mark.parametrize(
    "bad, says",
    [
        (["--prior-refresh", "1"], "prior_refresh must be a share in [0, 1), but got 1.0"),
        (["--walkers", "40"], "walkers must be an integer in [44, 4,096] (2 per material, 22 materials), but got 40"),
        (["--map-starts", "0"], "map_starts must be an integer in [1, 1,000] (one Gauss-Newton run), but got 0"),
        (["--seeds", "0"], "seeds must be an integer in [1, 10,000], but got 0"),
        # issue 53: sizes with no bound, and a least number of steps that gave "split R-hat max nan"
        (["--walkers", "5000000"], "walkers must be an integer in [44, 4,096]"),
        (["--particles", "5000000"], "particles must be an integer in [44, 4,096]"),
        (["--steps", "4"], f"steps must be an integer in [{MIN_STEPS}, 100,000]"),
        (["--steps", "10000000"], "steps must be an integer in [8, 100,000]"),
        (["--mcmc-steps", "100000"], "mcmc_steps must be an integer in [1, 1,000]"),
        (["--map-starts", "1000000"], "map_starts must be an integer in [1, 1,000]"),
        (["--seeds", "1000000"], "seeds must be an integer in [1, 10,000], but got 1000000"),
        (["--prior-refresh", "nan"], "prior_refresh must be a finite number in [0, 1], but got nan"),
        (["--walkers", "4096", "--steps", "10000"], "walkers x steps must be at most 4,000,000"),
    ],
)
def test_the_command_refuses_sampler_settings_out_of_range(bad, says, capsys):
    assert main(["posterior", "P1", *bad]) == 2  # a usage error, one line naming the setting and the value
    err = capsys.readouterr().err
    assert says in err and err.count("\n") == 1, err


@pytest.mark.parametrize(
    "field, value",
    [("sampler", "nuts"), ("walkers", 43), ("walkers", 48.0), ("steps", 3), ("particles", True), ("mcmc_steps", 0),
     ("prior_refresh", -0.1), ("prior_refresh", float("nan")), ("steps", MIN_STEPS - 1), ("walkers", 10**6),
     ("map_starts", 10**6)],
)  # fmt: skip
def test_sampler_settings_refuse_values_out_of_range(field, value):
    with pytest.raises(InputError, match=f"SamplerSettings.{field} must be"):
        SamplerSettings(**{field: value})


def test_sampler_settings_are_frozen_and_record_what_shapes_a_run():
    emcee, tempered = SamplerSettings(walkers=48, steps=8, map_starts=2), SamplerSettings("smc", particles=64)
    assert emcee.record() == {"walkers": 48, "steps": 8, "map_starts": 2, "prior_refresh": PRIOR_REFRESH}
    assert tempered.record() == {"particles": 64, "mcmc_steps": MCMC_STEPS, "map_starts": MAP_STARTS}
    with pytest.raises(dataclasses.FrozenInstanceError):
        emcee.steps = 4


def test_the_commands_defaults_are_the_samplers_own(capsys):
    with pytest.raises(SystemExit):
        main(["posterior", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    for flag, value in [("--steps", STEPS), ("--map-starts", MAP_STARTS)]:
        assert f"{flag.upper().lstrip('-').replace('-', '_')} " in text and f"default {value}" in text
    assert f"(default {PRIOR_REFRESH})" in text


def test_the_least_steps_give_a_finite_split_rhat():
    """At `MIN_STEPS` the kept half splits into halves of two steps, each with a variance: split R-hat is
    finite (issue 53: at the old least, 4, it was NaN and the command printed "split R-hat max nan")."""
    walkers = 2 * design.N_MATERIAL
    chain = np.random.default_rng(0).normal(size=(MIN_STEPS, walkers, design.N_MATERIAL))
    assert np.all(np.isfinite(mcmc.split_rhat(chain[MIN_STEPS // 2 :])))
    with warnings.catch_warnings():  # numpy warns of the variance of one step
        warnings.simplefilter("ignore", RuntimeWarning)
        assert np.all(np.isnan(mcmc.split_rhat(chain[:2])))  # 4 steps: 2 kept, halves of 1


def test_the_command_says_why_a_saved_runs_rhat_is_not_available():
    from wrist_env.cli.run.identification import _rhat

    assert _rhat(np.array([1.01, np.nan, 1.2])) == "split R-hat max 1.20"
    assert "not available" in _rhat(np.full(design.N_MATERIAL, np.nan))


def test_the_study_refuses_seeds_out_of_range_before_any_run(tmp_path):
    for seeds, says in [(0, "seeds must be an integer in [1, 10,000], but got 0"), ([-1], "seed must be an integer")]:
        with pytest.raises(InputError) as refused:
            study_.study(["P1"], seeds, tmp_path)
        assert says in str(refused.value)
    assert not any(tmp_path.iterdir())


def test_an_emcee_chain_larger_than_memory_holds_is_refused_before_it_runs():
    with pytest.raises(InputError, match=r"walkers x steps must be at most 4,000,000 .* 4,096 x 1,000 = 4,096,000"):
        SamplerSettings(walkers=4096, steps=1000)
    SamplerSettings("smc", walkers=4096, steps=1000)  # SMC has no chain: its walkers and steps are not used
