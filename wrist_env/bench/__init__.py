"""The calibration benchmark: one calibration (`calibrate`), the runner over participants ×
instances × calibrators × seeds (`benchmark`, `make_cells`), its Parquet run log (`RunLog`) and the leaderboards
(`write_leaderboard`). `wrist-bench calibrate | benchmark | leaderboard` are the commands."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from wrist_env.bench.calibrate import CalibrationRun, ResumeError, calibrate
from wrist_env.bench.cells import SEED_IS_INSTANCE, make_cells
from wrist_env.bench.log import RunLog
from wrist_env.bench.runner import BenchmarkReport, benchmark
from wrist_env.bench.schema import RunKey
from wrist_env.errors import DuplicateEvaluationError


def write_leaderboard(runs: str | Path, out: str | Path, **kwargs: Any) -> Path:
    """Write the leaderboards of the run log in `runs` to the folder `out` (see `leaderboard`).

    The leaderboard module is loaded when called, so that running a benchmark does not load matplotlib.

    Parameters
    ----------
    runs : str or Path
        The run log's folder (`RunLog`).
    out : str or Path
        The folder the tables, figures and README are written to (made if missing).
    **kwargs
        ``references`` and ``title``, as `wrist_env.bench.leaderboard.write_leaderboard` takes them.

    Returns
    -------
    Path
        ``out/README.md``.
    """
    from wrist_env.bench.leaderboard import write_leaderboard as write

    return write(runs, out, **kwargs)


__all__ = [
    "BenchmarkReport",
    "CalibrationRun",
    "DuplicateEvaluationError",
    "ResumeError",
    "RunKey",
    "RunLog",
    "SEED_IS_INSTANCE",
    "benchmark",
    "calibrate",
    "make_cells",
    "write_leaderboard",
]
