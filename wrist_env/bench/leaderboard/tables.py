"""The leaderboard's cost tables and what every table is made from: a run log's finished cells and
one row per run (pandas frames), best-so-far cost curves, cost targets, the best calibration cost and
the evaluations to reach each target (COCO's expected running time)."""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from pathlib import Path

import numpy as np
import pandas as pd
from numpy.typing import ArrayLike

from wrist_env.bench.leaderboard.reference import Reference, rmse_array
from wrist_env.bench.leaderboard.statistics import ert, ert_interval
from wrist_env.bench.log import RunLog
from wrist_env.bench.schema import key_of, summary_instance

TARGETS = (("pop×0.75", "population", 0.75), ("pop×0.5", "population", 0.5), ("truth×1.1", "truth", 1.1))
"""Cost targets (name, reference, factor): a target is factor × the reference design's cost on the
calibration trial. 0.75 and 0.5 × the population (Table 2 means) cost measure progress from the
uncalibrated model; 1.1 × the hidden truth's cost is "as good as the truth, within 10 %" (the truth
is not cost 0: the reference kinematics carry tracking noise and come from a finer model). A target
below what any design can reach (0.5 × population can be below the truth's cost) stays unsolved."""

ECDF_TARGETS = 51
ECDF_DECADES = 3.0
"""The ECDF's targets per participant, as COCO's (51 log-spaced precisions, Hansen et al. 2021,
Optim Methods Softw 36:114): f* + (f_pop − f*)·10^(−3k/50), k = 0..50, from the population design's
cost f_pop down to a thousandth of its distance to f*, the best cost any run of the log reached
(the optimum is unknown: COCO's "best known" convention)."""


def quantile(values: Iterable[float | None], q: float) -> float:
    values = np.asarray([v for v in values if v is not None and np.isfinite(v)], dtype=np.float64)
    return float(np.quantile(values, q)) if len(values) else np.nan


def runs_of(runs_frame: pd.DataFrame, problem: str, calibrator: str) -> pd.DataFrame:
    """The rows of `runs_frame` (one per run) of one problem (`problem_label`) and calibrator label."""
    return runs_frame[(runs_frame.problem == problem) & (runs_frame.calibrator == calibrator)]


def calibrator_label(optimizer: str, budget: int, budgets: set) -> str:
    return optimizer if len(budgets) == 1 else f"{optimizer} (budget {budget})"


def problem_label(participant: str, instance: int) -> str:
    """The name a leaderboard gives a problem: the participant's for instance 0 (as before instances), else
    "<participant>.i<instance>" (as in the cell names, `RunKey.name`)."""
    return participant if instance == 0 else f"{participant}.i{instance}"


def problem_of(problem: str) -> tuple[str, int]:
    """(participant, instance) of a problem's name (`problem_label`'s inverse): unambiguous, since a participant's
    name has no "." (`participants.folder.NAME_PATTERN`; the built-ins' neither)."""
    head, dot, tail = problem.rpartition(".i")
    return (head, int(tail)) if dot and tail.isdigit() else (problem, 0)


def problem_columns(problem: str) -> dict:
    """The columns naming a problem in a per-problem table: participant, instance and problem (its label)."""
    participant, instance = problem_of(problem)
    return {"participant": participant, "instance": instance, "problem": problem}


def load_runs(runs: str | Path) -> tuple[pd.DataFrame, list[dict], int]:
    """Read the evaluations of a run log's finished cells, their summaries and the count of unfinished cells.

    Parameters
    ----------
    runs : str or Path
        The run log's folder.

    Returns
    -------
    evals : pandas.DataFrame
        The finished cells' evaluations, one row each (the columns of `bench.schema.SCHEMA`).
    summaries : list of dict
        The finished cells' summaries.
    unfinished : int
        The number of cells with evaluations but no summary.

    Raises
    ------
    StoreError
        A damaged file in the log (the message names it).
    """
    log = RunLog(runs)
    evals = log.read()
    summaries = log.summaries()
    fields = ("participant", "optimizer", "seed", "budget", "instance")
    finished = {tuple(getattr(key_of(s), f) for f in fields) for s in summaries}
    keys = list(zip(*(evals[f] for f in fields)))
    mask = np.array([k in finished for k in keys], dtype=bool)
    unfinished = len(set(keys) - finished)
    return evals[mask].reset_index(drop=True), summaries, unfinished


def by_problem(evals: pd.DataFrame, summaries: list[dict]) -> tuple[pd.DataFrame, list[dict]]:
    """The evaluations and summaries with "participant" the problem's label (`problem_label`: the participant
    for instance 0, "P1.i3" for instance 3), the instance kept: the leaderboard's tables are per problem,
    so a log of instance 0 alone gives the tables it gave before instances."""
    evals = evals.assign(participant=[problem_label(p, k) for p, k in zip(evals.participant, evals.instance)])
    summaries = [
        s | {"participant": problem_label(s["participant"], summary_instance(s)), "instance": summary_instance(s)}
        for s in summaries
    ]
    return evals, summaries


def curves(evals: pd.DataFrame) -> dict:
    """{(participant, optimizer, seed, budget): best-so-far cost (nfev,)}."""
    out = {}
    for key, group in evals.groupby(["participant", "optimizer", "seed", "budget"], sort=True):
        out[key] = np.minimum.accumulate(group.sort_values("eval")["cost"].to_numpy())
    return out


def unsettled_shares(evals: pd.DataFrame) -> dict:
    """{(participant, optimizer, seed, budget): share of the run's simulated (not failed) evaluations with a
    frame whose hold ran out before equilibrium}; NaN for a run logged before the log recorded it."""
    out = {}
    for key, group in evals.groupby(["participant", "optimizer", "seed", "budget"], sort=True):
        ran = group[~group.failed.astype(bool)]
        u = ran["unsettled"].to_numpy(dtype=float)  # the log's schema gives older logs the column, null
        out[key] = float(np.mean(u > 0)) if len(u) and np.isfinite(u).all() else np.nan
    return out


def hit(curve: np.ndarray, target: float) -> int | None:
    """Evaluations (1-based count) until the best-so-far cost is ≤ target; None if never."""
    idx = np.flatnonzero(curve <= target)
    return int(idx[0]) + 1 if len(idx) else None


def spread(values: ArrayLike, prefix: str = "") -> dict[str, float]:
    """{prefix + "median", "q25", "q75"} of `values` (NaN-free quantiles, see `quantile`)."""
    return {f"{prefix}{name}": quantile(values, q) for name, q in (("median", 0.5), ("q25", 0.25), ("q75", 0.75))}


def best_cost(
    runs_frame: pd.DataFrame, refs: dict[str, Reference], participants: Iterable[str], labels: Sequence[str]
) -> pd.DataFrame:
    rows = []
    for p in participants:
        for label in labels:
            sub = runs_of(runs_frame, p, label)
            if sub.empty:
                continue
            v = sub.best_cost.to_numpy()
            unsettled = sub.calibrate_unsettled_frames.to_numpy(dtype=float)
            rows.append(
                {
                    **problem_columns(p),
                    "calibrator": label,
                    "runs": len(v),
                    **spread(v),
                    "min": float(v.min()),
                    "max": float(v.max()),
                    "population": refs[p].population["calibrate"]["cost"],
                    "truth": refs[p].truth["calibrate"]["cost"] if refs[p].truth else np.nan,
                    # runs whose calibrated design has a frame that did not settle (NaN: logged before it was)
                    "unsettled": float(np.sum(unsettled > 0)) if np.isfinite(unsettled).all() else np.nan,
                    # share of all the runs' evaluations with such a frame (NaN: logged before it was)
                    "unsettled_evals": float(sub.unsettled_evals.to_numpy(dtype=float).mean()),
                }
            )
    return pd.DataFrame(rows)


def pooled_best_cost(runs_frame: pd.DataFrame, labels: Sequence[str]) -> pd.DataFrame:
    """The best cost at the budget per participant and calibrator pooled over its instances, as the scale-free
    `relative_cost` (best / the instance's hidden-truth cost): median and IQR over all its runs (instances ×
    seeds); `population`: the median over its instances of the population design's cost relative to the truth."""
    rows = []
    for p in dict.fromkeys(runs_frame.participant):
        mine = runs_frame[runs_frame.participant == p]
        per_problem = mine.groupby("problem", sort=False)[["population_cost", "truth_cost"]].first()
        population = quantile(per_problem.population_cost / per_problem.truth_cost, 0.5)
        for label in labels:
            sub = mine[mine.calibrator == label]
            if not sub.empty:
                rows.append(
                    {
                        "participant": p,
                        "calibrator": label,
                        "instances": sub.instance.nunique(),
                        "runs": len(sub),
                        **spread(sub.relative_cost),
                        "population": population,
                    }
                )
    return pd.DataFrame(rows)


def evals_to_target(
    runs_frame: pd.DataFrame, targets: pd.DataFrame, participants: Sequence[str], labels: Sequence[str]
) -> pd.DataFrame:
    """COCO's expected running time (`statistics.ert`) per participant, target and calibrator over all the
    participant's runs — its instances × seeds, each instance's target its own (`targets`, per problem) —
    with the bootstrapped 90 % interval (`statistics.ert_interval`); `instances`: how many were pooled."""
    rows = []
    for p in participants:
        mine = targets[targets.problem.isin(runs_frame.problem[runs_frame.participant == p])]
        for name in dict.fromkeys(mine.target):
            problems = set(mine.problem[mine.target == name])
            for label in labels:
                sub = runs_frame[
                    (runs_frame.participant == p) & (runs_frame.calibrator == label) & runs_frame.problem.isin(problems)
                ]
                if sub.empty:
                    continue
                hits = sub[f"evals_to_{name}"].to_numpy(dtype=np.float64)  # NaN: never reached
                solved = np.isfinite(hits)
                spent = np.where(solved, hits, sub.nfev.to_numpy(dtype=np.float64))
                low, high = ert_interval(spent, solved)
                rows.append(
                    {
                        "participant": p,
                        "target": name,
                        "calibrator": label,
                        "instances": sub.instance.nunique(),
                        "solved": int(solved.sum()),
                        "runs": len(sub),
                        "ert": ert(spent, solved),
                        "ert_low": low,
                        "ert_high": high,
                        "median_evals_solved": float(np.median(hits[solved])) if solved.any() else np.nan,
                    }
                )
    return pd.DataFrame(rows)


def _targets(participants, refs) -> pd.DataFrame:
    rows = []
    for p in participants:
        r = refs[p]
        for name, base, factor in TARGETS:
            score = r.population if base == "population" else r.truth
            if score is not None:
                rows.append(
                    {
                        **problem_columns(p),
                        "target": name,
                        "reference": base,
                        "factor": factor,
                        "reference_cost": score["calibrate"]["cost"],
                        "value": factor * score["calibrate"]["cost"],
                    }
                )
    return pd.DataFrame(rows)


def ecdf_targets(participants: Iterable[str], refs: dict[str, Reference], curves_by_key: dict) -> pd.DataFrame:
    """`ECDF_TARGETS` log-spaced cost targets per problem (see `ECDF_TARGETS`): participant, instance, problem,
    k, value; `participants`: the problems' names."""
    rows = []
    for p in participants:
        ends = [float(np.min(c)) for key, c in curves_by_key.items() if key[0] == p and len(c)]
        start = refs[p].population["calibrate"]["cost"]
        if not ends:
            continue
        best = min(ends)
        for k in range(ECDF_TARGETS):
            precision = 10.0 ** (-ECDF_DECADES * k / (ECDF_TARGETS - 1))
            rows.append({**problem_columns(p), "k": k, "value": best + (start - best) * precision})
    return pd.DataFrame(rows, columns=["participant", "instance", "problem", "k", "value"])


def _runs_frame(summaries, curves_by_key, targets, budgets, unsettled_by_key, refs) -> pd.DataFrame:
    """One row per run: its key (participant, instance and the problem's name), costs — `relative_cost` the
    best cost over the problem's hidden-truth cost (NaN without a truth), the scale-free quantity that pools
    over instances —, recovery, held-out RMSE and evaluations to each target; unsettled_by_key:
    `unsettled_shares` of the run log; refs: {problem: `Reference`}."""
    rows = []
    for s in summaries:
        key = (s["participant"], s["optimizer"], s["seed"], s["budget"])
        curve = curves_by_key.get(key, np.array([s["best_cost"]]))
        truth = refs[s["participant"]].truth
        truth_cost = truth["calibrate"]["cost"] if truth is not None else np.nan
        row = {
            **problem_columns(s["participant"]),
            "calibrator": calibrator_label(s["optimizer"], s["budget"], budgets),
            "optimizer": s["optimizer"],
            "seed": s["seed"],
            "budget": s["budget"],
            "nfev": s["nfev"],
            "best_cost": s["best_cost"],
            "population_cost": refs[s["participant"]].population["calibrate"]["cost"],
            "truth_cost": truth_cost,
            "relative_cost": s["best_cost"] / truth_cost,
            "best_eval": s["best_eval"],
            "calibrate_cost": s["calibrate"]["cost"],
            # NaN in summaries logged before it was recorded; a failed design counts none
            "calibrate_unsettled_frames": (s["calibrate"]["unsettled_frames"] or 0)
            if "unsettled_frames" in s["calibrate"]
            else np.nan,
            "unsettled_evals": unsettled_by_key.get(key, np.nan),
            "validate_cost": s["validate"]["cost"],
            "validate_failed": s["validate"]["failed"],
            "recovery_z": s["recovery_z"],
        }
        val = rmse_array(s["validate"]["rmse"])
        row["validate_rmse_translation_mm"] = float(np.nanmean(val[:, :3])) if np.isfinite(val).any() else np.nan
        row["validate_rmse_rotation_deg"] = float(np.nanmean(val[:, 3:])) if np.isfinite(val).any() else np.nan
        for t in targets[targets.problem == s["participant"]].itertuples():
            row[f"evals_to_{t.target}"] = hit(curve, t.value)
        rows.append(row)
    return pd.DataFrame(rows)
