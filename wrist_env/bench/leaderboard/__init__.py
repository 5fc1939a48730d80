"""Leaderboards of a benchmark run log: tables (Markdown, CSV) and COCO-style figures (PNG).

`write_leaderboard(runs, out)` reads the run log in `runs` (finished cells
only) and writes to the folder `out`:

- best_cost.csv: best calibration cost at the budget per participant and calibrator, median and
  IQR (25th–75th percentile) over seeds; `unsettled`: runs whose calibrated design has a frame whose
  hold ran out before equilibrium; `unsettled_evals`: the share of the runs' evaluations with one;
- targets.csv, evals_to_target.csv: evaluations to reach each cost target (TARGETS), the number
  of runs that reached it and COCO's expected running time (ERT);
- ecdf.png: COCO-style ECDF of (run, target) pairs solved against evaluations;
  convergence.png: best-so-far cost against evaluations, median and IQR band per calibrator,
  one panel per participant;
- recovery.csv: parameter-recovery error (RMS z-score difference to the hidden truth);
- heldout.csv: the calibrated design (best of each run) on the held-out resisted trial;
- table3_rmse_calibrate.csv, table4_rmse_validate.csv: the preprint's Tables 3–4, per participant,
  bone and DOF: RMSE of the population and the calibrated design (the best run per participant);
  dof_improved.csv: the share of DOF whose RMSE calibration lowered (preprint: 66.7 %, 61.1 %);
- runs.csv: one row per run; README.md: all tables in Markdown with the figures.

Problem instances (`participants.instances`): every table, column and panel "per participant" is per
problem, a participant's instance, named by the participant for instance 0 (so a log of instance 0
alone gives the leaderboard it gave before instances) and "<participant>.i<k>" for instance k
(`tables.problem_label`; the CSVs' `participant` column holds that name, runs.csv also the instance);
each problem's targets and references are its own population's and hidden truth's costs on its trials.

Nothing here depends on wall-clock time, so an interrupted-and-resumed
benchmark gives the same CSVs as an uninterrupted one.
"""

from __future__ import annotations

from pathlib import Path

from wrist_env.bench.leaderboard.board import Leaderboard, build, write_csvs
from wrist_env.bench.leaderboard.readme import readme
from wrist_env.bench.leaderboard.reference import Reference, reference
from wrist_env.bench.leaderboard.tables import TARGETS, load_runs

__all__ = ["TARGETS", "Leaderboard", "Reference", "build", "load_runs", "reference", "write_leaderboard"]


def write_leaderboard(
    runs: str | Path, out: str | Path, *, references: dict[str, Reference] | None = None, title: str | None = None
) -> Path:
    """Write the leaderboards of the run log in `runs` into the folder `out`; returns out/README.md.

    references: {problem (the participant for instance 0): `Reference`} already simulated (the others are
    simulated here)."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    board = build(runs, references)
    write_csvs(board, out)
    from wrist_env.figures import leaderboard as figures  # here, not above: it imports this package

    colors = figures.colors(board.labels)
    figures.convergence_figure(out / "convergence.png", board, colors)
    figures.ecdf_figure(out / "ecdf.png", board, colors)
    path = out / "README.md"
    path.write_text(readme(board, title))
    return path
