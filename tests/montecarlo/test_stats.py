"""The mixed models recover effects planted in a synthetic run log, before they meet the solver."""

import numpy as np
import patsy
import pyarrow as pa
import pytest

from wrist_env.errors import InputError
from wrist_env.ligaments import INJURABLE, LIGAMENT_NAMES
from wrist_env.montecarlo import stats

ANGLES = np.linspace(40.0, -40.0, 17)
PRESSURE_TEARS = {"SLIL_v": 0.0, "SLIL_p": 0.1, "SLIL_d": 0.8, "RSC": 0.3, "LRL": -0.05}  # MPa
SPLINE = (1.3, -1.8, -0.3)  # intercept (full extension), s1, s2, MPa
SLIL_TRUTH = {
    "Intercept": 27.8,
    "s1": -42.6,
    "s2": -6.6,
    "proximal": -25.7,
    "volar": -1.6,
    "s1:proximal": 44.8,
    "s2:proximal": 4.6,
}  # the preprint's Table 6, N


def synthetic_runs(n_runs=800, seed=0) -> pa.Table:
    """A run log (the columns the statistics read) with known fixed effects, random intercepts and noise."""
    rng = np.random.default_rng(seed)
    b = stats.angle_basis(ANGLES, -40.0, 40.0)
    curve = SPLINE[0] + b @ np.array(SPLINE[1:])
    torn = rng.random((n_runs, 5)) < 0.3
    shift = torn @ np.array([PRESSURE_TEARS[l] for l in INJURABLE])
    pressure = curve + shift[:, None] + rng.normal(0, 0.4, (n_runs, 1)) + rng.normal(0, 0.15, (n_runs, 17))
    t = SLIL_TRUTH
    dorsal = t["Intercept"] + b @ np.array([t["s1"], t["s2"]])
    bundles = {
        "SLIL_d": dorsal,
        "SLIL_v": dorsal + t["volar"],
        "SLIL_p": dorsal + t["proximal"] + b @ np.array([t["s1:proximal"], t["s2:proximal"]]),
    }
    u = rng.normal(0, 3.0, (n_runs, 1))
    cols = {
        "participant": np.where(np.arange(n_runs) % 2, "P2", "P1"),
        "sample_id": np.arange(n_runs) // 2,
        "ok": np.ones(n_runs, bool),
        "excluded": np.zeros(n_runs, bool),
    }
    cols["excluded"][:5] = True  # excluded runs are left out of the fits
    for i, lig in enumerate(INJURABLE):
        cols[f"{lig}.torn"] = torn[:, i]

    def frames(x):
        return pa.array(list(np.broadcast_to(x, (n_runs, 17))), type=pa.list_(pa.float64()))

    cols["angle_deg"] = frames(ANGLES)
    cols["rs_mean_mpa"] = frames(pressure)
    cols["rs_peak_mpa"] = frames(2 * pressure)
    cols["rs_area_mm2"] = frames(np.full(17, 10.0))
    for lig in LIGAMENT_NAMES:
        force = bundles.get(lig, np.zeros(17)) + (u + rng.normal(0, 1.0, (n_runs, 17)) if lig in bundles else 0)
        cols[f"{lig}.force_n"] = frames(force)
    return pa.table(cols)


@pytest.fixture(scope="module")
def frames():
    return stats.frame_table(synthetic_runs())


def test_angle_basis_is_patsys_bs_df2():
    x = np.linspace(-40, 40, 17)
    expected = np.asarray(patsy.dmatrix("bs(x, df=2, degree=2) - 1", {"x": x}))
    assert np.allclose(stats.angle_basis(x, -40, 40), expected, atol=1e-12)


def test_frame_table_keeps_included_runs(frames):
    assert frames["group"].nunique() == 800 - 5 and len(frames) == (800 - 5) * 17
    assert set(frames["participant"]) == {"P1", "P2"}


def test_pressure_model_recovers_planted_tear_effects(frames):
    """The planted +0.8 MPa of a dorsal SLIL tear within 2 SE; all eight coefficients within 3 SE (eight
    at once at 2 SE fail a third of the seeds by chance alone: over 12 seeds the z-scores here had mean
    −0.2 and SD 0.9, i.e. unbiased and well calibrated)."""
    fit = stats.fit_pressure(frames)
    t = fit.table.set_index("term")
    assert abs(t.loc["SLIL_d", "estimate"] - 0.8) < 2 * t.loc["SLIL_d", "se"], t.loc["SLIL_d"].to_dict()
    for lig, truth in PRESSURE_TEARS.items():
        assert abs(t.loc[lig, "estimate"] - truth) < 3 * t.loc[lig, "se"], (lig, t.loc[lig].to_dict())
    for term, truth in zip(("Intercept", "s1", "s2"), SPLINE):
        assert abs(t.loc[term, "estimate"] - truth) < 3 * t.loc[term, "se"], term
    assert t.loc["SLIL_d", "significant"] and not t.loc["SLIL_v", "significant"]
    assert t.loc["SLIL_d", "pct_of_mean"] == pytest.approx(100 * t.loc["SLIL_d", "estimate"] / fit.mean_response)
    assert abs(fit.group_variance - 0.16) < 0.04 and fit.converged
    # a documented subsample fits on fewer runs and still finds the big effect
    sub = stats.fit_pressure(frames, max_runs=200, seed=1)
    assert sub.runs == 200 and sub.rows == 200 * 17
    assert (
        abs(sub.table.set_index("term").loc["SLIL_d", "estimate"] - 0.8)
        < 3 * sub.table.set_index("term").loc["SLIL_d", "se"]
    )


def test_slil_model_recovers_planted_bundle_differences(frames):
    fit = stats.fit_slil(frames)
    t = fit.table.set_index("term")
    intact = frames.loc[frames["any_injury"] == 0, "group"].nunique()
    assert fit.runs == intact and fit.rows == intact * 17 * 3
    assert abs(t.loc["volar", "estimate"] - SLIL_TRUTH["volar"]) < 2 * t.loc["volar", "se"]  # the preprint's −1.6 N
    for term, truth in SLIL_TRUTH.items():
        assert abs(t.loc[term, "estimate"] - truth) < 3 * t.loc[term, "se"], (term, t.loc[term].to_dict())


def test_summary_numbers_at_30_degrees_extension(frames):
    s = stats.summary_numbers(frames)
    assert s["angle_deg"] == -30.0 and set(s) == {"all", "P1", "P2", "angle_deg"}
    at = frames[np.isclose(frames["angle"], -30) & (frames["any_injury"] == 0)]
    total = at[["SLIL_v.force_n", "SLIL_p.force_n", "SLIL_d.force_n"]].sum(axis=1).mean()
    assert s["all"]["intact_total_slil_force_at_angle_n"] == pytest.approx(total)


def test_too_few_runs_is_a_fit_error_naming_the_least_it_takes():
    """A tiny study's fit raised numpy's 'Singular matrix': it says how many runs Table 5 needs instead."""
    frames = stats.frame_table(synthetic_runs(n_runs=5 + stats.MIN_RUNS_TABLE5 - 1))  # the first 5 are excluded
    with pytest.raises(stats.FitError, match=r"Table 5 needs at least 7 runs, but the study has 6 to fit"):
        stats.fit_pressure(frames)
    assert stats.MIN_RUNS_TABLE5 == 7  # the intercept, five tears and the variance between runs


def test_a_tear_seen_in_no_run_is_a_fit_error_naming_it(frames):
    intact = frames.assign(RSC=0.0)
    with pytest.raises(stats.FitError, match=r"each tear both present and absent, but in all 795 runs RSC intact"):
        stats.fit_pressure(intact)


@pytest.mark.parametrize("max_runs", [0, -5, 1, stats.MIN_FIT_RUNS - 1, 2.5])
def test_a_subset_smaller_than_the_fit_needs_is_refused_saying_how_many(frames, max_runs):
    """Fewer runs than Table 5's intercept and tear indicators cannot be fitted: refused before the fit,
    naming the least (issue 53: --max-runs 0, -5 and 1 ended in tracebacks)."""
    with pytest.raises(InputError, match=rf"max_runs must be an integer in \[{stats.MIN_FIT_RUNS}, "):
        stats.fit_pressure(frames, max_runs=max_runs)
    assert stats.MIN_FIT_RUNS == 2 + len(INJURABLE)


def test_a_subset_the_model_cannot_fit_is_one_error_naming_it(frames):
    """Runs in which a tear never occurs leave its column constant: a `FitError` naming the tear, not
    statsmodels' LinAlgError."""
    never_torn = frames[frames["SLIL_v"] == 0]
    with pytest.raises(stats.FitError, match=r"each tear both present and absent, .* SLIL_v intact"):
        stats.fit_pressure(never_torn)
