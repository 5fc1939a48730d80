"""A third-party calibrator installed through the entry point appears in `wrist-bench benchmark`."""

import os
import subprocess
import sys
from pathlib import Path

import pandas as pd

REPO = Path(__file__).resolve().parents[2]


def test_third_party_optimizer_runs_in_the_benchmark(third_party_optimizer, built, tmp_path):
    built("P1")  # cached for the subprocess (WRIST_ENV_CACHE is inherited)
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [env.get("PYTHONPATH"), str(REPO)]))
    out = tmp_path / "bench"
    done = subprocess.run(
        [
            sys.executable,
            "-m",
            "wrist_env.cli",
            "benchmark",
            "--participants",
            "P1",
            "--seeds",
            "1",
            "--budget",
            "3",
            "--workers",
            "1",
            "--no-progress",
            "--storage",
            "memory",
            "--out",
            str(out),
        ],
        env=env,
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert done.returncode == 0, done.stderr[-2000:]
    assert third_party_optimizer in done.stdout
    log = pd.concat([pd.read_parquet(p) for p in (out / "evals").glob("*.parquet")])
    assert (log["optimizer"] == third_party_optimizer).sum() == 3
