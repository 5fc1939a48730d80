"""The likelihood and the prior (`wrist_env.identification.likelihood`) and the `+prior` (MAP) calibrators."""

import numpy as np
import pytest
from scipy.integrate import quad

from wrist_env import design, table2
from wrist_env.bench import RunLog, calibrate
from wrist_env.frames import error_dof
from wrist_env.identification import likelihood
from wrist_env.model import BONES
from wrist_env.task import task


def test_the_scale_free_likelihood_is_the_gaussian_one_integrated_over_jeffreys_noise():
    """∫ N(r | 0, σ²) dσ/σ ∝ (Σ r²)^(−n/2): the log ratio of two residual sets by quadrature equals
    `log_likelihood`'s, for each group (translations, rotations) separately."""
    rng = np.random.default_rng(0)
    a, b = rng.normal(size=(2, 3, 6)), rng.normal(size=(2, 3, 6))
    b[..., :3] *= 2.0  # a different translation scale

    def log_marginal(r):
        total = 0.0
        for group in (r[..., :3], r[..., 3:]):
            s, n = float(np.sum(group**2)), group.size
            f = lambda log_sigma: np.exp(-n * log_sigma - s / (2 * np.exp(2 * log_sigma)) + 0.5 * s)  # noqa: E731
            total += np.log(quad(f, -10, 10, limit=200)[0]) - 0.5 * s
        return total

    expected = log_marginal(a) - log_marginal(b)
    assert likelihood.log_likelihood(a) - likelihood.log_likelihood(b) == pytest.approx(expected, rel=1e-6)


def test_the_prior_is_table_2_truncated_to_the_action_box():
    z = np.zeros((3, design.N_MATERIAL))
    z[1, 4] = 2.0
    z[2, 7] = 3.01
    lp = likelihood.log_prior(z)
    assert lp[0] == 0.0 and lp[1] == pytest.approx(-2.0) and lp[2] == -np.inf


@pytest.mark.slow
def test_map_objective_is_the_misfit_over_the_noise_plus_the_prior(built):
    """On P1's calibration trial: ½ Σ (error / NOISE)² of the scaphoid and lunate frames + ½ |z|²."""
    built("P1")
    t = task("P1", "calibrate")
    z = np.linspace(-1, 1, design.N_MATERIAL)
    d = table2.with_z(design.population(), z)
    e = t.evaluate(d)
    misfit = 0.0
    for b, bone in enumerate(("scaphoid", "lunate")):
        i = BONES.index(bone)
        err = error_dof(e.result.poses[:, i], t.reference[b], t.model.centroid[i])
        misfit += 0.5 * np.sum((err / likelihood.NOISE) ** 2)
    assert likelihood.map_objective(t, e, z) == pytest.approx(misfit + 0.5 * np.sum(z**2), rel=1e-9)
    assert misfit > 10  # the population design does not fit P1 within the noise


@pytest.mark.slow
def test_a_prior_calibrator_logs_its_objective_and_resumes(built, tmp_path):
    """`random+prior`: the log keeps the cost and the MAP objective told to the calibrator; the summary's
    best_cost is the calibrated design's cost; a cut run resumes by replaying the objective."""
    built("P1")
    run = calibrate("P1", "random+prior", 6, 0, log=tmp_path / "runs")
    rows = RunLog(tmp_path / "runs").read()
    assert len(rows) == 6 and (rows.objective > 10 * rows.cost).all()
    best = int(np.argmin(rows.objective))
    s = run.to_dict()
    assert s["objective"] == "map" and s["best_objective"] == pytest.approx(rows.objective[best])
    assert s["best_cost"] == pytest.approx(run.calibrate["cost"]) == pytest.approx(rows.cost[best])
    for summary in (tmp_path / "runs" / "cells").glob("*.json"):
        summary.unlink()  # as if killed after its last batch: every evaluation replays from the log
    again = calibrate("P1", "random+prior", 6, 0, log=tmp_path / "runs")
    assert again.replayed == 6 and again.result.fun == pytest.approx(run.result.fun)


@pytest.mark.slow
def test_benchmark_prior_runs_every_calibrator_with_and_without_it(built, tmp_path):
    built("P1")
    from wrist_env.cli import main

    out = tmp_path / "runs"
    args = ["benchmark", "--participants", "P1", "--optimizers", "random", "--prior", "--seeds", "1"]
    assert main(args + ["--budget", "3", "--storage", "memory", "--out", str(out), "--no-progress"]) == 0
    summaries = {s["optimizer"]: s for s in RunLog(out).summaries()}
    assert sorted(summaries) == ["random", "random+prior"]
    assert summaries["random"]["objective"] == "cost" and summaries["random+prior"]["objective"] == "map"
    import pandas as pd

    recovery = pd.read_csv(out / "leaderboards" / "recovery.csv")
    assert sorted(recovery.calibrator) == ["random", "random+prior"]
