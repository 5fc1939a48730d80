"""The wrist problems in IOHexperimenter (`ioh`, the optional `[ioh]` extra), and benchmark logs for IOHanalyzer.

`problem("P1")` is participant P1's calibration as an `ioh` real single-objective
problem: the 22 normalized material variables in [-1, 1] (injury scalars intact,
as the benchmark's cells), the kinematic cost on the calibration trial, minimized;
any `ioh` logger attaches to it. Named "wrist-<participant>"; `ioh` numbers
wrapped problems itself. `problem("P1", 3)` is its problem instance 3
(`participants.instances`), as `ioh.get_problem(fid, instance, dim)` gives a
function's instance: the same function id, the instance in ioh's meta data
(`meta_data.instance`, the logs' "instance"); instance 0 is the shipped problem.

`export(runs, out)` writes a benchmark run log in IOHanalyzer's format through
`ioh`'s own `Analyzer` logger: each logged evaluation is replayed, in the
calibrator's order, into a problem whose value is the logged cost (nothing is
simulated again). One folder per calibrator (its algorithm name), one problem
per participant, one run per (instance, seed), each run carrying its instance id;
positions stored. A calibrator's earlier folder in `out` is replaced. (Before
instances every run was exported as ioh instance 1; it is now the run's instance,
0 for the shipped problem.)
"""

from __future__ import annotations

import shutil
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from wrist_env import design
from wrist_env.bench.calibrate import action
from wrist_env.bench.log import RunLog
from wrist_env.bench.schema import X_COLUMNS
from wrist_env.design import N_MATERIAL
from wrist_env.errors import InputError
from wrist_env.task import task

if TYPE_CHECKING:
    import ioh

PROBLEM_PREFIX = "wrist-"


def _wrap(participant: str, instance: int, function) -> ioh.problem.RealSingleObjective:
    import ioh

    return ioh.wrap_problem(
        function,
        name=f"{PROBLEM_PREFIX}{participant}",
        dimension=N_MATERIAL,
        instance=instance,
        optimization_type=ioh.OptimizationType.MIN,
        lb=-1.0,
        ub=1.0,
    )


def problem(participant: str, instance: int = 0) -> ioh.problem.RealSingleObjective:
    """Participant's calibration on its problem `instance` (0: the shipped problem) as an `ioh` problem: x (22,)
    normalized materials in [-1, 1] → kinematic cost on the instance's calibration trial; the instance is
    ioh's (`meta_data.instance`)."""

    calibration = task(participant, "calibrate", instance=instance)

    def cost(x: np.ndarray) -> float:
        return float(calibration.evaluate_batch([design.from_action(action(np.asarray(x)))])[0].cost)

    return _wrap(participant, instance, cost)


def export(runs: str | Path, out: str | Path) -> list[Path]:
    """IOHanalyzer files of the benchmark run log in `runs`, written under `out`; returns the calibrator folders."""
    import ioh

    log = RunLog(Path(runs))
    table = log.read()
    if table.empty:
        raise InputError(f"no evaluations are logged in {Path(runs) / 'evals'}: run `wrist-bench benchmark` first.")
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    replay: list[float] = []
    problems = {
        (p, k): _wrap(p, int(k), lambda x: replay.pop(0))
        for p, k in sorted(set(zip(table["participant"], table["instance"])))
    }
    folders = []
    for (optimizer, budget), cells in table.groupby(["optimizer", "budget"], sort=True):
        folder = f"{optimizer}-budget{budget}" if table["budget"].nunique() > 1 else str(optimizer)
        shutil.rmtree(out / folder, ignore_errors=True)  # ioh would write beside it, as "<folder>-1"
        logger = ioh.logger.Analyzer(
            root=str(out),
            folder_name=folder,
            algorithm_name=str(optimizer),
            algorithm_info=f"wrist-env benchmark, {budget} evaluations per run, one run per instance and seed",
            store_positions=True,
        )
        for problem_key, runs_of_problem in cells.groupby(["participant", "instance"], sort=True):
            f = problems[problem_key]
            f.attach_logger(logger)
            for _, run in runs_of_problem.groupby("seed", sort=True):
                run = run.sort_values("eval")
                replay[:] = run["cost"].tolist()
                for x in run[list(X_COLUMNS)].to_numpy():
                    f(x)
                f.reset()
            f.detach_logger()
        logger.close()
        folders.append(out / folder)
    return folders
