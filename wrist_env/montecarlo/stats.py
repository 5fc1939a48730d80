"""Mixed-effects statistics of the Monte Carlo log (preprint 2.3.2.2, Tables 5–6), with statsmodels.

Rows: the frames of the included runs (the solver succeeded, not excluded).
The wrist angle enters as a 2-df spline: `angle_basis`, the quadratic
B-spline basis without interior knots on the sweep's range (exactly patsy's
`bs(angle, df=2, degree=2)`, a test checks), so the intercept is the value at
the range's lower end — full extension, −40° (angles are flexion +) — and the
two basis coefficients shape the curve towards neutral and full flexion.

Table 5 (`fit_pressure`): MixedLM, REML,
    rs_mean_mpa ~ s1 + s2 + SLIL_v + SLIL_p + SLIL_d + RSC + LRL,  random intercept per run,
where each tear indicator is 1 when that ligament is torn and the group is
the run (participant, sample id: one material sample). The participant is not a
fixed effect (the preprint's table has none); its offset is carried by the
random intercepts. Estimates are also given as % of the mean pressure over
all rows. statsmodels reports z (Wald) statistics where the preprint's GLME
reported t; at these sizes the two coincide.

Table 6 (`fit_slil`): intact runs only, one row per run, frame and SLIL
bundle (dorsal = base, proximal, volar), MixedLM, REML,
    force_n ~ s1 + s2 + proximal + volar + s1:proximal + s2:proximal,  random intercept per run,
the preprint's layout (its "Random Scalar" row is not defined in its text and
is left out).

Size: at the preprint's full size (25,000 runs × 17 frames = 425,000 rows)
a fit takes tens of seconds here, so it is done on every row by default.
`max_runs` fits on the frames of a seeded random subset of runs instead
(the choice and the subset size are reported with the table).

Too few runs: with a random intercept per run, the run-level terms (the intercept and, in Table 5, the five
tears) are told apart only between runs, so a fit needs more runs than those terms (`MIN_RUNS_TABLE5`,
`MIN_RUNS_TABLE6`) and each tear both present and absent. A fit short of them (or whose matrix is singular)
raises `FitError` saying so, instead of a LinAlgError.
"""

from __future__ import annotations

import time
import warnings
from collections.abc import Iterable
from dataclasses import dataclass, field

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.compute as pc
from numpy.typing import ArrayLike

from wrist_env.errors import WristEnvError
from wrist_env.ligaments import INJURABLE
from wrist_env.limits import MAX_SUBSET_RUNS, check_int
from wrist_env.montecarlo.config import FIT_RUNS_WHY, MIN_FIT_RUNS

ALPHA = 0.001
SLIL = ("SLIL_v", "SLIL_p", "SLIL_d")
BUNDLE_LABELS = {"SLIL_v": "Volar SLIL", "SLIL_p": "Proximal SLIL", "SLIL_d": "Dorsal SLIL", "RSC": "RSC", "LRL": "LRL"}
PRESSURE_FORMULA = "rs_mean_mpa ~ s1 + s2 + " + " + ".join(INJURABLE)
SLIL_FORMULA = "force_n ~ s1 + s2 + proximal + volar + s1:proximal + s2:proximal"
MIN_RUNS_TABLE5 = MIN_FIT_RUNS
"""Fewest included runs Table 5's fit takes (`config.MIN_FIT_RUNS`)."""
MIN_RUNS_TABLE6 = 2
"""Fewest intact runs Table 6's fit takes (its one run-level term is the intercept)."""


MORE_RUNS = "run a larger study (--n), or fit more of its runs (--max-runs)"


class FitError(WristEnvError, ValueError):
    """A mixed-effects fit that the runs cannot support (too few, a tear never or always present)."""


def angle_basis(angle: ArrayLike, lower: float, upper: float) -> np.ndarray:
    """(n, 2): the quadratic B-spline basis on [lower, upper] without interior knots, minus its
    first function (the intercept's): b1 = 2 t (1 − t), b2 = t², t = (angle − lower) / (upper − lower).
    Equal to patsy's `bs(angle, df=2, degree=2)` when [lower, upper] is the data's range."""
    t = (np.asarray(angle, dtype=np.float64) - lower) / (upper - lower)
    return np.stack([2.0 * t * (1.0 - t), t * t], axis=-1)


def _flat(table: pa.Table, column: str) -> np.ndarray:
    return pc.list_flatten(table[column]).to_numpy(zero_copy_only=False).astype(np.float64)


def included(runs: pa.Table) -> pa.Table:
    """The runs the statistics use: the solver succeeded and the run was not excluded."""
    mask = pc.and_(runs["ok"], pc.invert(runs["excluded"]))
    return runs.filter(mask)


def frame_table(runs: pa.Table) -> pd.DataFrame:
    """One row per frame of each included run (`included`): participant, sample_id,
    group ("P1:17"), frame, angle (deg, flexion +), rs_mean_mpa, rs_peak_mpa, rs_area_mm2, the tear
    indicators (0/1, named by ligament), any_injury, and the SLIL bundle forces (N)."""
    runs = included(runs)
    n = runs.num_rows
    lengths = pc.list_value_length(runs["angle_deg"]).to_numpy(zero_copy_only=False)
    parent = np.repeat(np.arange(n), lengths)
    frame = np.concatenate([np.arange(k) for k in lengths]) if n else np.zeros(0, int)
    participant = np.asarray(runs["participant"].to_numpy(zero_copy_only=False), dtype=object)
    sample = runs["sample_id"].to_numpy()
    out = {
        "participant": participant[parent],
        "sample_id": sample[parent],
        "group": (pd.Series(participant, dtype=str) + ":" + pd.Series(sample).astype(str)).to_numpy()[parent],
        "frame": frame,
        "angle": _flat(runs, "angle_deg"),
    }
    for c in ("rs_mean_mpa", "rs_peak_mpa", "rs_area_mm2"):
        out[c] = _flat(runs, c)
    torn = np.zeros((n, len(INJURABLE)))
    for i, lig in enumerate(INJURABLE):
        torn[:, i] = runs[f"{lig}.torn"].to_numpy(zero_copy_only=False)
        out[lig] = torn[parent, i]
    out["any_injury"] = (torn.sum(axis=1) > 0).astype(float)[parent]
    for lig in SLIL:
        out[f"{lig}.force_n"] = _flat(runs, f"{lig}.force_n")
    return pd.DataFrame(out)


def subsample_runs(frames: pd.DataFrame, max_runs: int | None, seed: int = 0) -> tuple[pd.DataFrame, int]:
    """The frames of at most `max_runs` runs (a seeded random subset of groups); (frames, runs kept).
    `max_runs` is checked first: at least `MIN_FIT_RUNS`, at most `MAX_SUBSET_RUNS`."""
    check_max_runs(max_runs)
    groups = frames["group"].unique()
    if max_runs is None or len(groups) <= max_runs:
        return frames, len(groups)
    keep = np.random.default_rng(seed).choice(groups, size=int(max_runs), replace=False)
    return frames[frames["group"].isin(set(keep))], int(max_runs)


def check_max_runs(max_runs: int | None) -> int | None:
    """`max_runs` (None: every run) if it is an integer in [`MIN_FIT_RUNS`, `MAX_SUBSET_RUNS`]; `InputError`
    saying how many runs the fit needs at least."""
    if max_runs is None:
        return None
    return check_int("max_runs", max_runs, MIN_FIT_RUNS, MAX_SUBSET_RUNS, FIT_RUNS_WHY)


@dataclass
class Fit:
    """A fitted table: one row per fixed effect (estimate, SE, z, p, significant at ALPHA)."""

    table: pd.DataFrame
    mean_response: float
    group_variance: float
    residual_variance: float
    runs: int
    rows: int
    runs_available: int
    seconds: float
    converged: bool
    formula: str
    extra: dict = field(default_factory=dict)

    def info(self) -> dict:
        return {
            "formula": self.formula,
            "runs": self.runs,
            "rows": self.rows,
            "runs_available": self.runs_available,
            "mean_response": self.mean_response,
            "group_variance": self.group_variance,
            "residual_variance": self.residual_variance,
            "fit_seconds": round(self.seconds, 2),
            "converged": self.converged,
            **self.extra,
        }


def _mixedlm(formula: str, data: pd.DataFrame, table: str, min_runs: int, kind: str = "runs"):
    """The REML fit of `formula` on `data` with a random intercept per run; `FitError` naming `table`
    and `min_runs` (of `kind`) if the runs cannot support it (`_check_runs`) or its matrix turns out singular."""
    import statsmodels.formula.api as smf
    from statsmodels.tools.sm_exceptions import ConvergenceWarning

    _check_runs(data, table, min_runs, kind)
    model = smf.mixedlm(formula, data, groups=data["group"])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ConvergenceWarning)
        try:
            result = model.fit(reml=True)
        except np.linalg.LinAlgError as e:
            raise FitError(
                f"the mixed-effects fit of {table} hit a singular matrix ({e}) on its {data['group'].nunique():,} "
                f"{kind}: too few or too alike to tell the variance between runs from the fixed effects (it needs "
                f"at least {min_runs} {kind}, and more when they are alike); {MORE_RUNS}"
            ) from None
    return result


def _check_runs(data: pd.DataFrame, table: str, min_runs: int, kind: str) -> None:
    """`FitError` unless `data` holds at least `min_runs` runs, each tear column it has both 0 and 1 among
    them."""
    runs = data["group"].nunique()
    if runs < min_runs:
        raise FitError(
            f"the mixed-effects fit of {table} needs at least {min_runs} {kind}, but the study has {runs:,} "
            f"to fit: {MORE_RUNS}"
        )
    constant = [lig for lig in INJURABLE if lig in data and data[lig].nunique() < 2]
    if constant:
        states = ", ".join(f"{lig} {'torn' if data[lig].iloc[0] else 'intact'}" for lig in constant)
        raise FitError(
            f"the mixed-effects fit of {table} needs each tear both present and absent, but in all {runs:,} runs "
            f"{states}: {MORE_RUNS}"
        )


def _table(result, rows: list[tuple[str, str, str]], mean: float | None) -> pd.DataFrame:
    out = []
    for section, name, label in rows:
        est, se = float(result.fe_params[name]), float(result.bse_fe[name])
        z = est / se if se > 0 else float("nan")
        p = float(result.pvalues[name])
        row = {"section": section, "parameter": label, "term": name, "estimate": est}
        if mean is not None:
            row["pct_of_mean"] = 100.0 * est / mean
        row.update({"se": se, "z": z, "p": p, "significant": bool(p < ALPHA)})
        out.append(row)
    return pd.DataFrame(out)


def _prepare(frames: pd.DataFrame, max_runs: int | None, seed: int):
    available = frames["group"].nunique()
    frames, runs = subsample_runs(frames, max_runs, seed)
    lower, upper = float(frames["angle"].min()), float(frames["angle"].max())
    frames = frames.copy()
    frames[["s1", "s2"]] = angle_basis(frames["angle"].to_numpy(), lower, upper)
    return frames, runs, available, (lower, upper)


def fit_pressure(frames: pd.DataFrame, *, max_runs: int | None = None, seed: int = 0) -> Fit:
    """Table 5: radioscaphoid mean pressure on the angle spline and the five tear indicators."""
    start = time.perf_counter()
    data, runs, available, bounds = _prepare(frames, max_runs, seed)
    result = _mixedlm(PRESSURE_FORMULA, data, "Table 5", MIN_RUNS_TABLE5)
    mean = float(data["rs_mean_mpa"].mean())
    rows = [
        ("Angle spline", "Intercept", "Intercept (full extension)"),
        ("Angle spline", "s1", "Angle spline 1"),
        ("Angle spline", "s2", "Angle spline 2"),
    ]
    rows += [("Ligament injury", lig, BUNDLE_LABELS[lig]) for lig in INJURABLE]
    return _fit(
        _table(result, rows, mean), mean, result, PRESSURE_FORMULA, data, runs, available, start, bounds, max_runs, seed
    )


def slil_long(frames: pd.DataFrame) -> pd.DataFrame:
    """Intact runs' frames, one row per SLIL bundle: group, angle, bundle, proximal, volar, force_n."""
    intact = frames[frames["any_injury"] == 0]
    parts = []
    for lig in SLIL:
        part = intact[["participant", "group", "sample_id", "frame", "angle"]].copy()
        part["bundle"] = lig
        part["proximal"] = float(lig == "SLIL_p")
        part["volar"] = float(lig == "SLIL_v")
        part["force_n"] = intact[f"{lig}.force_n"].to_numpy()
        parts.append(part)
    return pd.concat(parts, ignore_index=True)


def fit_slil(frames: pd.DataFrame, *, max_runs: int | None = None, seed: int = 0) -> Fit:
    """Table 6: SLIL bundle forces in intact runs (dorsal the base), angle spline, proximal interactions."""
    start = time.perf_counter()
    data, runs, available, bounds = _prepare(slil_long(frames), max_runs, seed)
    result = _mixedlm(SLIL_FORMULA, data, "Table 6", MIN_RUNS_TABLE6, "intact runs")
    rows = [
        ("Angle spline", "Intercept", "Intercept (dorsal SLIL, full extension)"),
        ("Angle spline", "s1", "Angle spline 1"),
        ("Angle spline", "s2", "Angle spline 2"),
        ("Ligament", "proximal", "Proximal SLIL"),
        ("Ligament", "volar", "Volar SLIL"),
        ("Ligament", "s1:proximal", "Angle spline 1 × proximal"),
        ("Ligament", "s2:proximal", "Angle spline 2 × proximal"),
    ]
    mean = float(data["force_n"].mean())
    return _fit(
        _table(result, rows, None), mean, result, SLIL_FORMULA, data, runs, available, start, bounds, max_runs, seed
    )


def _fit(table, mean, result, formula, data, runs, available, start, bounds, max_runs, seed) -> Fit:
    """A `Fit` from a fitted MixedLM `result` on `data` (timed from `start`, perf_counter s)."""
    return Fit(
        table,
        mean,
        float(result.cov_re.iloc[0, 0]),
        float(result.scale),
        runs,
        len(data),
        available,
        time.perf_counter() - start,
        bool(result.converged),
        formula,
        {"angle_range_deg": list(bounds), "max_runs": max_runs, "subsample_seed": seed},
    )


def pressure_curve(fit: Fit, angles: ArrayLike, torn: Iterable[str] = ()) -> np.ndarray:
    """Table 5's fixed-effect prediction of the mean pressure (MPa) at `angles` with ligaments `torn`."""
    est = dict(zip(fit.table["term"], fit.table["estimate"]))
    lower, upper = fit.extra["angle_range_deg"]
    b = angle_basis(angles, lower, upper)
    return est["Intercept"] + b[:, 0] * est["s1"] + b[:, 1] * est["s2"] + sum(est[lig] for lig in torn)


def injury_category(run_flags: pd.DataFrame) -> pd.Series:
    """Per run: "Intact", "Partial SLIL" (one or two SLIL bundles), "Full SLIL" (all three; RSC and LRL
    intact in both) or "Other": Figure 9's groups."""
    slil = run_flags[list(SLIL)].sum(axis=1)
    extrinsic = run_flags[["RSC", "LRL"]].sum(axis=1)
    cat = pd.Series("Other", index=run_flags.index)
    cat[(slil == 0) & (extrinsic == 0)] = "Intact"
    cat[(slil > 0) & (slil < 3) & (extrinsic == 0)] = "Partial SLIL"
    cat[(slil == 3) & (extrinsic == 0)] = "Full SLIL"
    return cat


FIG9_GROUPS = ("Intact", "Partial SLIL", "Full SLIL", "Any injury")
"""Figure 9's boxes: three `injury_category` values, then every run with any tear."""


def full_extension(frames: pd.DataFrame) -> pd.DataFrame:
    """The runs' rows at full extension (the smallest angle), with their `injury_category` as `category`."""
    at = frames[np.isclose(frames["angle"], frames["angle"].min())].copy()
    at["category"] = injury_category(at).to_numpy()
    return at


def summary_numbers(frames: pd.DataFrame, angle: float = -30.0) -> dict:
    """Numbers beside the preprint's: mean radioscaphoid pressure over all included frames (Table 5's
    normalizer; preprint 0.65 MPa), and at `angle` (default 30° extension) the mean pressure of all and
    of intact runs, and the total SLIL force of intact runs (mean ± SD; preprint 26.0 N, cadaveric
    20.0 ± 3.3 N). Per participant and pooled."""
    out = {}
    for name, part in [("all", frames)] + list(frames.groupby("participant")):
        at = part[np.isclose(part["angle"], angle)]
        intact_at = at[at["any_injury"] == 0]
        total = intact_at[[f"{l}.force_n" for l in SLIL]].sum(axis=1)
        out[str(name)] = {
            "runs": int(part["group"].nunique()),
            "intact_runs": int(part.loc[part["any_injury"] == 0, "group"].nunique()),
            "mean_pressure_mpa": float(part["rs_mean_mpa"].mean()),
            "pressure_at_angle_mpa": float(at["rs_mean_mpa"].mean()) if len(at) else float("nan"),
            "intact_pressure_at_angle_mpa": float(intact_at["rs_mean_mpa"].mean()) if len(intact_at) else float("nan"),
            "intact_total_slil_force_at_angle_n": float(total.mean()) if len(total) else float("nan"),
            "intact_total_slil_force_at_angle_sd_n": float(total.std()) if len(total) > 1 else float("nan"),
        }
    out["angle_deg"] = angle
    return out
