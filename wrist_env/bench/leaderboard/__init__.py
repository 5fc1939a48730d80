"""Leaderboards of a benchmark run log: tables (Markdown, CSV) and COCO-style figures (PNG).

`write_leaderboard(runs, out)` reads the run log in `runs` (finished cells
only) and writes to the folder `out`.

Problems and instances (`participants.instances`): a problem is a participant's instance — COCO's function
and instance: the participant is the function, instance 0 its shipped hidden truth and trials, instance
k ≥ 1 a truth drawn from the population prior with its own synthetic trials. Each problem's targets and
references are its own population's and hidden truth's costs on its trials. Tables per problem carry
`participant`, `instance` and `problem` (the participant's name for instance 0, "<participant>.i<k>" for
instance k, `tables.problem_label`); the Markdown tables and the figures' panels are per participant,
pooling its instances (a log of instance 0 alone: one instance per participant, its seeds pooled).

Per problem:

- best_cost.csv: best calibration cost at the budget per problem and calibrator, median and IQR
  (25th–75th percentile) over seeds, with the population's and hidden truth's costs; `unsettled`: runs whose
  calibrated design has a frame whose hold ran out before equilibrium; `unsettled_evals`: the share of the
  runs' evaluations with one;
- targets.csv: the cost targets (TARGETS) of each problem; ecdf_targets.csv: the ECDF's targets;
- recovery.csv: parameter-recovery error (RMS z-score difference to the hidden truth), with the population
  design's error on that problem (the baseline);
- heldout.csv: the calibrated design (best of each run) on the held-out resisted trial;
- table3_rmse_calibrate.csv, table4_rmse_validate.csv: the preprint's Tables 3–4, per problem,
  bone and DOF: RMSE of the population and the calibrated design (the best run per problem);
  dof_improved.csv: the share of DOF whose RMSE calibration lowered (preprint: 66.7 %, 61.1 %);
- runs.csv: one row per run (with `relative_cost`, its best cost over its instance's hidden-truth cost).

Per participant, pooled over its instances (`statistics`):

- best_relative.csv: best cost relative to the instance's hidden-truth cost, median and IQR over all runs;
- evals_to_target.csv: runs that reached each target, COCO's expected running time (ERT) and its
  bootstrapped 90 % interval (`ert_low`, `ert_high`; inf: an open end);
- recovery_pooled.csv: the recovery error, median and IQR over all runs;
- convergence.png: best-so-far cost relative to the truth's against evaluations, median and IQR band per
  calibrator; ecdf.png: COCO-style ECDF of (run, target) pairs solved against evaluations, all problems
  and per participant.

Over all problems: ranking.csv: the calibrators' mean ranks (a problem is a block, the score its best cost
relative to the truth's, median over seeds), with Friedman's test and the Nemenyi critical difference
(`autorank`), ranking.png its critical-difference diagram and ranking_report.txt autorank's own report
(only with the test: 5 or more problems, 3 or more calibrators); README.md: all tables in Markdown with the figures.

Nothing here depends on wall-clock time, so an interrupted-and-resumed
benchmark gives the same CSVs as an uninterrupted one.
"""

from __future__ import annotations

from pathlib import Path

from wrist_env.bench.leaderboard.board import Leaderboard, build, write_csvs
from wrist_env.bench.leaderboard.curves import convergence_panels, ecdf_panels
from wrist_env.bench.leaderboard.readme import ranking_title, readme
from wrist_env.bench.leaderboard.reference import Reference, reference
from wrist_env.bench.leaderboard.tables import TARGETS, load_runs
from wrist_env.figures import leaderboard as figures

__all__ = ["TARGETS", "Leaderboard", "Reference", "build", "load_runs", "reference", "write_leaderboard"]


def write_leaderboard(
    runs: str | Path, out: str | Path, *, references: dict[str, Reference] | None = None, title: str | None = None
) -> Path:
    """Write the leaderboards of the run log in `runs` into the folder `out`.

    The CSV tables (`board.CSV_FILES`), the convergence, ECDF and (when the ranking is tested) ranking
    figures, and a README that shows them.

    Parameters
    ----------
    runs : str or Path
        The run log's folder (`RunLog`).
    out : str or Path
        The folder written to (made if missing).
    references : dict of str to Reference, optional
        ``{problem (the participant for instance 0): Reference}`` already simulated (the others are
        simulated here).
    title : str, optional
        The README's title.

    Returns
    -------
    Path
        ``out/README.md``.

    Raises
    ------
    StoreError
        The run log has no finished cell, a damaged file, or a cell made on another model or trials than
        today's.
    """
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    board = build(runs, references)
    write_csvs(board, out)
    colors, budget = figures.colors(board.labels), max(board.budgets)
    figures.convergence_figure(out / "convergence.png", convergence_panels(board), colors, budget)
    figures.ecdf_figure(out / "ecdf.png", ecdf_panels(board), colors, budget)
    diagram, report = out / "ranking.png", out / "ranking_report.txt"
    if board.ranking.tested:
        figures.ranking_figure(diagram, board.ranking.result, ranking_title(board.ranking))
        report.write_text(board.ranking.report + "\n")
    else:  # those of an earlier log in this folder would be another ranking's
        diagram.unlink(missing_ok=True)
        report.unlink(missing_ok=True)
    path = out / "README.md"
    path.write_text(readme(board, title))
    return path
