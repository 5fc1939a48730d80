"""Monte Carlo injury study (preprint 2.3.2): sampler, run log, study runner, statistics, report.

`run_study(StudyConfig(("P1", "P2"), n=12500, seed=0), "runs/montecarlo")` runs it
(`wrist-bench montecarlo`); `wrist_env.montecarlo.report.write_report` writes Tables 5–6 and
Figures 8–10 from the log (`wrist-bench montecarlo-report`).
"""

from wrist_env.montecarlo.config import StudyConfig, StudyError
from wrist_env.montecarlo.log import read_runs
from wrist_env.montecarlo.study import run_study

__all__ = ["StudyConfig", "StudyError", "read_runs", "run_study"]
