"""Monte Carlo injury study (preprint 2.3.2): sampler, run log, study runner, statistics, report.

`run_study(StudyConfig(("P1", "P2"), n=12500, seed=0), "runs/montecarlo")` runs it
(`wrist-bench montecarlo`); `wrist_env.montecarlo.report.write_report` writes Tables 5–6 and
Figures 8–10 from the log (`wrist-bench montecarlo-report`).

`StudyConfig` (`config`) loads neither the run log (pyarrow) nor the solver: `read_runs` and `run_study`
are imported on first use, so that the command line declares `montecarlo`'s options from the config.
"""

from importlib import import_module

from wrist_env.montecarlo.config import StudyConfig, StudyError

__all__ = ["StudyConfig", "StudyError", "read_runs", "run_study"]

_OWNERS = {"read_runs": "wrist_env.montecarlo.log", "run_study": "wrist_env.montecarlo.study"}


def __getattr__(name: str):
    """`read_runs` (`log`) and `run_study` (`study`), their modules imported on first use."""
    if name in _OWNERS:
        return getattr(import_module(_OWNERS[name]), name)
    raise AttributeError(f"module 'wrist_env.montecarlo' has no attribute {name!r}")
