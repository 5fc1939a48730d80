"""The Monte Carlo study on the solver: the same log twice, on a LocalCluster, after a kill; exclusions; report."""

import os
import re
import shutil
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

from wrist_env.design import NAMES
from wrist_env.errors import StoreError
from wrist_env.montecarlo import StudyConfig, StudyError, read_runs, run_study
from wrist_env.montecarlo.sampler import FRAME_COLUMNS, SCHEMA, TEAR_COLUMNS
from wrist_env.runs import StoreBusyError
from wrist_env.solver.settings import DEFAULT_LOADS

pytestmark = pytest.mark.slow  # builds models or runs simulations/studies (minutes)

CONFIG = StudyConfig(("P1",), n=40, seed=3)


@pytest.fixture(scope="module")
def reference(built, tmp_path_factory):
    """The uninterrupted study in this process, batch 5: its folder and log."""
    built("P1")
    out = tmp_path_factory.mktemp("mc_reference")
    summary = run_study(CONFIG, out, batch=5)
    assert summary.done and summary.counts["P1"].succeeded == 40
    return out, read_runs(out)


def test_log_rows_hold_the_design_tears_and_frames(reference):
    out, log = reference
    assert log.schema.equals(SCHEMA)
    assert log["sample_id"].to_pylist() == list(range(log.num_rows))
    rows = log.to_pylist()
    ok = [r for r in rows if r["ok"]]
    assert sum(r["ok"] and not r["excluded"] for r in rows) == 40
    for r in ok:
        assert all(len(r[c]) == 17 for c in FRAME_COLUMNS)
        assert r["angle_deg"][0] == 40.0 and r["angle_deg"][-1] == -40.0
        assert all(r[t] == (r[n] < 0) for t, n in zip(TEAR_COLUMNS, NAMES[22:]))
        for t in TEAR_COLUMNS:  # a torn ligament carries no load
            if r[t]:
                assert max(r[t.replace(".torn", ".force_n")]) == 0.0
    for r in rows:
        if not r["ok"]:
            assert r["status"] != "ok" and r["rs_mean_mpa"] is None and r["angle_deg"] is not None
    assert not any(p.name.startswith(".") for p in (out / "runs").iterdir())


def test_seeded_log_is_identical_twice_with_another_batch_size(reference, tmp_path):
    summary = run_study(CONFIG, tmp_path, batch=7)
    assert summary.simulated == reference[1].num_rows
    assert read_runs(tmp_path).equals(reference[1])
    # rerunning a finished study simulates nothing and changes nothing
    again = run_study(CONFIG, tmp_path, batch=7)
    assert again.simulated == 0 and again.done and read_runs(tmp_path).equals(reference[1])


def test_seeded_log_is_identical_on_a_local_cluster(reference, tmp_path):
    from distributed import LocalCluster

    with LocalCluster(
        n_workers=1, threads_per_worker=1, host="127.0.0.1", dashboard_address=None, processes=True
    ) as cluster:
        summary = run_study(CONFIG, tmp_path, batch=8, scheduler=cluster.scheduler_address)
    assert summary.done
    assert read_runs(tmp_path).equals(reference[1])


def test_seeded_log_is_identical_on_local_worker_processes(reference, tmp_path):
    summary = run_study(CONFIG, tmp_path, batch=6, workers=2)
    assert summary.done and read_runs(tmp_path).equals(reference[1])


def _start_cli_study(out, batch=2, workers=0):
    """`wrist-bench montecarlo` on P1 (CONFIG's study) as a subprocess."""
    cmd = [
        sys.executable,
        "-m",
        "wrist_env.cli",
        "montecarlo",
        "P1",
        "--n",
        "40",
        "--seed",
        "3",
        "--batch",
        str(batch),
        "--workers",
        str(workers),
        "--out",
        str(out),
        "--no-progress",
    ]
    return subprocess.Popen(cmd, env=dict(os.environ), stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)


def _wait_for_parts(proc, out, n: int, seconds: float = 120) -> None:
    runs, deadline = out / "runs", time.monotonic() + seconds
    while time.monotonic() < deadline and proc.poll() is None:
        if runs.is_dir() and len(list(runs.glob("*.parquet"))) >= n:
            return
        time.sleep(0.01)
    assert proc.poll() is None, f"the study ended too soon: {proc.stderr.read().decode()[-2000:]}"


def test_killed_study_resumes_with_no_run_lost_or_repeated(reference, tmp_path):
    proc = _start_cli_study(tmp_path)
    try:
        _wait_for_parts(proc, tmp_path, 3)
        os.kill(proc.pid, signal.SIGKILL)
    finally:
        proc.wait(timeout=30)
    partial = read_runs(tmp_path)
    assert partial is not None and 0 < partial.num_rows < reference[1].num_rows
    summary = run_study(CONFIG, tmp_path, batch=5)
    assert summary.done and summary.simulated == reference[1].num_rows - partial.num_rows
    assert read_runs(tmp_path).equals(reference[1])


def test_a_second_run_on_the_same_folder_is_refused_while_one_runs(reference, tmp_path):
    proc = _start_cli_study(tmp_path)
    try:
        _wait_for_parts(proc, tmp_path, 1)
        with pytest.raises(StoreBusyError, match=r"pid \d+.*Monte Carlo"):
            run_study(CONFIG, tmp_path, batch=7)
        assert proc.wait(timeout=300) == 0, proc.stderr.read().decode()[-2000:]
    finally:
        if proc.poll() is None:
            proc.kill()
    assert read_runs(tmp_path).equals(reference[1])  # nothing duplicated by the refused run
    assert run_study(CONFIG, tmp_path, batch=7).simulated == 0  # the lock is free once the first run ended


@pytest.mark.parametrize("damage", ["truncated", "empty", "garbage"])
def test_a_damaged_part_is_named_then_resimulated(reference, tmp_path, damage):
    shutil.copytree(reference[0], tmp_path, dirs_exist_ok=True)
    part = sorted((tmp_path / "runs").glob("*.parquet"))[2]
    data = part.read_bytes()
    part.write_bytes({"truncated": data[: len(data) // 2], "empty": b"", "garbage": b"not parquet" * 10}[damage])
    with pytest.raises(StoreError, match=re.escape(part.name) + ".*rerun the montecarlo command"):
        read_runs(tmp_path)
    with pytest.warns(UserWarning, match=re.escape(part.name)):
        summary = run_study(CONFIG, tmp_path, batch=5)
    assert summary.done and 0 < summary.simulated <= 5
    assert read_runs(tmp_path).equals(reference[1])
    assert (tmp_path / "damaged" / part.name).is_file()  # kept for inspection


def test_killing_the_parent_kills_its_workers(reference, tmp_path, kill_parent):
    import psutil

    proc = _start_cli_study(tmp_path, batch=2, workers=2)
    try:
        _wait_for_parts(proc, tmp_path, 1)
        children = psutil.Process(proc.pid).children(recursive=True)
        assert len([c for c in children if "spawn" in " ".join(c.cmdline())]) >= 2
        kill_parent(proc, children)
    finally:
        if proc.poll() is None:
            proc.kill()


def test_excluded_runs_are_flagged_counted_and_replaced(built, tmp_path):
    config = StudyConfig(("P1",), n=8, seed=3, exclude_above_mpa=3.0)
    summary = run_study(config, tmp_path, batch=4)
    log = read_runs(tmp_path).to_pandas()
    c = summary.counts["P1"]
    assert c.succeeded == 8 and c.excluded > 0 and c.attempts == len(log) == 8 + c.excluded + c.failed
    assert ((log["ok"]) & (~log["excluded"])).sum() == 8
    peak = log["rs_mean_mpa"].map(lambda x: -1.0 if x is None else np.max(x))
    assert (log["excluded"] == (log["ok"] & (peak > 3.0))).all()
    assert log["block"].max() == c.blocks - 1 >= 1
    assert summary.excluded == c.excluded and "excluded" in summary.line()


def test_another_study_in_the_same_folder_is_refused(reference):
    out, _ = reference
    with pytest.raises(StudyError, match="seed"):
        run_study(StudyConfig(("P1",), n=40, seed=4), out)


def test_report_writes_tables_and_figures(reference, tmp_path):
    from wrist_env import cli

    out, _ = reference
    assert cli.main(["montecarlo-report", "--runs", str(out), "--out", str(tmp_path)]) == 0
    for name in (
        "table5.md",
        "table5.csv",
        "table6.md",
        "table6.csv",
        "figure8.png",
        "figure9.png",
        "figure10.png",
        "summary.json",
        "report.md",
    ):
        assert (tmp_path / name).stat().st_size > 100, name
    import pandas as pd

    t5 = pd.read_csv(tmp_path / "table5.csv")
    assert list(t5["term"]) == ["Intercept", "s1", "s2", "SLIL_v", "SLIL_p", "SLIL_d", "RSC", "LRL"]
    assert "| Ligament injury | Volar SLIL |" in (tmp_path / "table5.md").read_text()


def test_report_sets_the_preprints_tables_beside_ours_and_compares_signs(reference, tmp_path):
    """report.md and summary.json carry the preprint's Tables 5-6 estimates beside ours: every injury
    row has both, its sign verdict follows the two estimates' signs, and the spline's rows have none."""
    import json

    from wrist_env.montecarlo.report import PREPRINT_TABLE5, write_report

    out, _ = reference
    write_report(out, tmp_path)
    summary = json.loads((tmp_path / "summary.json").read_text())
    rows = {r["term"]: r for r in summary["beside_preprint"]["table5"]}
    assert set(rows) == set(PREPRINT_TABLE5)
    for term, r in rows.items():
        assert r["preprint_estimate"] == PREPRINT_TABLE5[term][0]
        if term in ("Intercept", "s1", "s2"):
            assert r["sign"] is None
        else:
            agree = (r["preprint_estimate"] > 0) == (r["estimate"] > 0)
            assert r["sign"] == ("same" if agree else "differs"), r
    text = (tmp_path / "report.md").read_text()
    assert "## Beside the preprint" in text and "| RSC | 0.304 | 0.005 |" in text
    assert summary["study"]["load_direction"] == DEFAULT_LOADS
