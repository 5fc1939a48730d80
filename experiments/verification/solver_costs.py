"""Do the two solvers rank the benchmark's designs alike? The calibration cost under both (issue 32).

Reads every design the committed benchmark logged (`leaderboards/iohanalyzer/*/data_*/*.dat`: each
calibrator's improving designs, 22 normalized materials in [-1, 1], injuries intact) and scores each
on the participant's calibration trial with the diagonal mass (`SolverSettings().diagonal()`, the default until issue 52)
and with the block mass (the defaults), batched. Prints per participant: designs, Spearman's ρ and
Kendall's τ of the two costs, the median and largest |Δ cost|, the share of designs whose cost moves
by more than 1 %, and the simulations that failed under one solver only.

Run: `python experiments/verification/solver_costs.py [P1 P2 P3]` (about a minute per participant on 2 cores).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
from scipy import stats

from wrist_env import design
from wrist_env.bench.calibrate import action
from wrist_env.solver.settings import SolverSettings
from wrist_env.task import Task

LOGS = Path(__file__).resolve().parents[2] / "leaderboards" / "iohanalyzer"


def logged_designs(participant: str) -> np.ndarray:
    """(n, 22) the normalized materials of every design the benchmark logged for `participant`."""
    rows = []
    for path in sorted(LOGS.glob(f"*/data_*_wrist-{participant}/*.dat")):
        for line in path.read_text().splitlines():
            fields = line.split()
            if fields and fields[0].isdigit():
                rows.append([float(v) for v in fields[2:]])
    return np.unique(np.asarray(rows), axis=0)


def costs(participant: str, settings: SolverSettings, xs: np.ndarray) -> np.ndarray:
    """Calibration cost of each design (NaN where the run failed)."""
    task = Task(participant, "calibrate", settings=settings)
    evaluations = task.evaluate_batch([design.from_action(action(x)) for x in xs])
    return np.array([np.nan if e.failed else e.cost for e in evaluations])


def main(participants: list[str]) -> None:
    print(
        "| participant | designs | Spearman ρ | Kendall τ | median / largest abs Δ cost | moved > 1 % | failed: diagonal only / block only |"
    )
    print("|---|---|---|---|---|---|---|")
    for p in participants:
        xs = logged_designs(p)
        a = costs(p, SolverSettings().diagonal(), xs)
        b = costs(p, SolverSettings(), xs)
        ok = np.isfinite(a) & np.isfinite(b)
        rho = stats.spearmanr(a[ok], b[ok]).statistic
        tau = stats.kendalltau(a[ok], b[ok]).statistic
        delta = np.abs(a[ok] - b[ok])
        moved = np.mean(delta > 0.01 * np.abs(a[ok]))
        only_a = int(np.sum(~np.isfinite(a) & np.isfinite(b)))
        only_b = int(np.sum(np.isfinite(a) & ~np.isfinite(b)))
        print(
            f"| {p} | {len(xs)} | {rho:.4f} | {tau:.4f} | {np.median(delta):.4f} / {delta.max():.3f} | "
            f"{moved:.1%} | {only_a} / {only_b} |"
        )


if __name__ == "__main__":
    main(sys.argv[1:] or ["P1", "P2", "P3"])
