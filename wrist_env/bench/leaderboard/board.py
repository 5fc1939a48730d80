"""The leaderboard: every table and curve of a run log's finished cells, computed once
(`Leaderboard`, `build`), and the CSV files it is written to."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from wrist_env.bench.leaderboard.accuracy import best_runs, dof_improved, heldout, pooled_recovery, recovery, rmse_table
from wrist_env.bench.leaderboard.reference import Reference, reference
from wrist_env.bench.leaderboard.statistics import Ranking, rank
from wrist_env.bench.leaderboard.tables import (
    _runs_frame,
    _targets,
    best_cost,
    by_problem,
    calibrator_label,
    curves,
    ecdf_targets,
    evals_to_target,
    load_runs,
    pooled_best_cost,
    problem_label,
    unsettled_shares,
)
from wrist_env.bench.log import RunLog
from wrist_env.bench.schema import summary_instance
from wrist_env.errors import StoreError
from wrist_env.runs import provenance


@dataclass(frozen=True)
class Leaderboard:
    """Everything a leaderboard shows, computed once from a run log (`build`).

    Per problem (a participant's instance): targets, ecdf_targets, best, recovery, heldout, table3, table4
    (columns participant, instance, problem); per participant, pooled over its instances: best_pooled, ert,
    recovery_pooled; over all problems: ranking. `CSV_FILES` names the file each table is written to. Costs
    are the kinematic cost (dimensionless); RMSEs are mm and deg.

    Parameters
    ----------
    runs : str
        The run log's folder.
    summaries : list of dict, length n_runs
        The finished cells' summaries (`bench.schema.SUMMARY_KEYS`), "participant" the problem's name.
    unfinished : int
        Cells of the log without a summary (left out).
    participants : list of str, length n_problems
        The problems: the participant, ``"<participant>.i<k>"`` for instance k ≥ 1.
    subjects : list of str
        The participants (the functions whose instances the problems are), in the problems' order.
    labels : list of str
        The calibrators' labels (the name, with its budget when the log has several budgets).
    budgets : set of int
        The budgets of the runs.
    refs : dict of str to Reference
        ``{problem: Reference}``: the population and hidden-truth designs scored.
    curves : dict
        ``{(participant, optimizer, seed, budget): best-so-far cost, shape (nfev,)}``.
    targets : pandas.DataFrame
        The cost targets (`TARGETS`) per problem.
    ecdf_targets : pandas.DataFrame
        The log-spaced cost targets of the ECDF per problem.
    runs_frame : pandas.DataFrame
        One row per run: its key, costs (`relative_cost`: over the hidden-truth cost), recovery, held-out
        RMSE and evaluations to each target.
    best : pandas.DataFrame
        The best calibration cost at the budget per problem and calibrator.
    ert : pandas.DataFrame
        Expected running time (evaluations) to each target per participant and calibrator.
    recovery : pandas.DataFrame
        Parameter-recovery error (`recovery_z`, Table 2 SD units) per problem and calibrator.
    heldout : pandas.DataFrame
        The held-out trial's cost and RMSE per problem and calibrator.
    chosen : dict of str to dict
        Per problem, the summary of the run with the lowest calibration cost.
    table3, table4 : pandas.DataFrame
        RMSE per bone and DOF (mm, deg) of the chosen run, the population and the truth, on the calibration
        trial (table3) and the held-out trial (table4).
    improved : pandas.DataFrame
        The DOFs the calibrated designs improve over the population design.
    best_pooled : pandas.DataFrame
        The best cost relative to the truth's per participant and calibrator, pooled over its instances.
    recovery_pooled : pandas.DataFrame
        The recovery error per participant and calibrator, pooled over its instances.
    ranking : Ranking
        The calibrators ranked over the problems (Friedman and Nemenyi when there are enough).
    """

    runs: str
    summaries: list
    unfinished: int
    participants: list  # the problems: the participant, "<participant>.i<k>" for instance k ≥ 1
    subjects: list  # the participants (the functions whose instances the problems are), in the problems' order
    labels: list
    budgets: set
    refs: dict
    curves: dict
    targets: pd.DataFrame
    ecdf_targets: pd.DataFrame
    runs_frame: pd.DataFrame
    best: pd.DataFrame
    ert: pd.DataFrame
    recovery: pd.DataFrame
    heldout: pd.DataFrame
    chosen: dict
    table3: pd.DataFrame
    table4: pd.DataFrame
    improved: pd.DataFrame
    best_pooled: pd.DataFrame
    recovery_pooled: pd.DataFrame
    ranking: Ranking


def build(runs: str | Path, references: dict[str, Reference] | None = None) -> Leaderboard:
    """The leaderboard of the finished cells of the run log in `runs`.

    Tables per problem (`tables.by_problem`: named by the participant for instance 0, "P1.i3" for instance
    3), per participant pooled over its instances, and the ranking over problems.

    Parameters
    ----------
    runs : str or Path
        The run log's folder.
    references : dict of str to Reference, optional
        ``{problem: Reference}`` already simulated; the others are simulated here.

    Returns
    -------
    Leaderboard
        Every table, curve and the ranking.

    Raises
    ------
    StoreError
        No finished benchmark cell in the run log, a damaged file, or a cell made on another model or
        trials than today's.
    """
    evals, summaries, unfinished = load_runs(runs)
    if not summaries:
        raise StoreError(f"{runs}: no finished benchmark cell in this run log")
    problems = sorted({(s["participant"], summary_instance(s)) for s in summaries})
    RunLog(runs).check_made_from({pk: provenance.of_participant(*pk) for pk in problems})  # today's models
    evals, summaries = by_problem(evals, summaries)
    participants = [problem_label(*pk) for pk in problems]
    order = {p: i for i, p in enumerate(participants)}
    summaries = sorted(summaries, key=lambda s: (order[s["participant"]], s["optimizer"], s["budget"], s["seed"]))
    budgets = {s["budget"] for s in summaries}
    labels = sorted({calibrator_label(s["optimizer"], s["budget"], budgets) for s in summaries})
    refs = dict(references or {})
    for (p, k), name in zip(problems, participants):
        if name not in refs:
            refs[name] = reference(p, k)
    by_key = curves(evals)
    targets = _targets(participants, refs)
    runs_frame = _runs_frame(summaries, by_key, targets, budgets, unsettled_shares(evals), refs)
    chosen = best_runs(summaries)
    subjects = list(dict.fromkeys(p for p, _ in problems))
    return Leaderboard(
        str(runs),
        summaries,
        unfinished,
        participants,
        subjects,
        labels,
        budgets,
        refs,
        by_key,
        targets,
        ecdf_targets(participants, refs, by_key),
        runs_frame,
        best_cost(runs_frame, refs, participants, labels),
        evals_to_target(runs_frame, targets, subjects, labels),
        recovery(runs_frame, summaries, participants, labels),
        heldout(runs_frame, refs, participants, labels),
        chosen,
        rmse_table(chosen, refs, participants, "calibrate"),
        rmse_table(chosen, refs, participants, "validate"),
        dof_improved(summaries, chosen, refs, participants, labels, budgets),
        pooled_best_cost(runs_frame, labels),
        pooled_recovery(runs_frame, summaries, labels),
        rank(runs_frame, labels),
    )


CSV_FILES = {
    "best_cost.csv": ("best", "%.6g"),
    "best_relative.csv": ("best_pooled", "%.6g"),
    "targets.csv": ("targets", "%.6g"),
    "ecdf_targets.csv": ("ecdf_targets", "%.6g"),
    "evals_to_target.csv": ("ert", "%.6g"),
    "recovery.csv": ("recovery", "%.6g"),
    "recovery_pooled.csv": ("recovery_pooled", "%.6g"),
    "heldout.csv": ("heldout", "%.6g"),
    "table3_rmse_calibrate.csv": ("table3", "%.4g"),
    "table4_rmse_validate.csv": ("table4", "%.4g"),
    "dof_improved.csv": ("improved", "%.4g"),
    "runs.csv": ("runs_frame", "%.6g"),
    "ranking.csv": ("ranking.table", "%.6g"),
}
"""The CSV files of a leaderboard: {file name: (Leaderboard field, float format)}."""


def write_csvs(board: Leaderboard, out: Path) -> None:
    for name, (field, float_format) in CSV_FILES.items():
        frame = board
        for part in field.split("."):
            frame = getattr(frame, part)
        frame.to_csv(out / name, index=False, float_format=float_format)
