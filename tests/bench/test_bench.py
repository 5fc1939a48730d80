"""The benchmark: run log, runner (local processes, kill-and-resume, dask), leaderboards, CLI."""

import json
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import optimizers
import wrist_env
from wrist_env.bench import DuplicateEvaluationError, ResumeError, RunKey, RunLog, benchmark, calibrate
from wrist_env.bench.calibrate import accepts_storage
from wrist_env.bench.leaderboard import write_leaderboard
from wrist_env.bench.schema import KEY_FIELDS
from wrist_env.cli import main
from wrist_env.errors import StoreError

pytestmark = pytest.mark.slow  # builds models or runs simulations/studies (minutes)

REPO = Path(wrist_env.__file__).resolve().parent.parent
TINY = ["random", "lhs"] if "lhs" in optimizers.available() else ["random"]
LEADERBOARD_FILES = (
    "README.md",
    "best_cost.csv",
    "evals_to_target.csv",
    "recovery.csv",
    "heldout.csv",
    "table3_rmse_calibrate.csv",
    "table4_rmse_validate.csv",
    "dof_improved.csv",
    "runs.csv",
    "targets.csv",
    "best_relative.csv",
    "recovery_pooled.csv",
    "ranking.csv",
    "ecdf.png",
    "convergence.png",
)


@pytest.fixture(scope="module")
def p1(built):
    built("P1")  # in the session's model cache, which subprocesses and dask workers inherit
    return "P1"


def _duplicates(frame) -> int:
    return int(frame.duplicated(list(KEY_FIELDS) + ["eval"]).sum())


def test_tiny_benchmark_logs_every_evaluation_once_and_writes_the_leaderboard(p1, tmp_path):
    report = benchmark([p1], TINY, 2, 12, tmp_path / "runs", workers=2, progress=False)
    assert not report.failed and len(report.ran) == len(TINY) * 2 and report.workers == 2
    rows = RunLog(tmp_path / "runs").read(dedupe=False)
    assert len(rows) == 1 * len(TINY) * 2 * 12
    assert _duplicates(rows) == 0 and np.isfinite(rows.cost).all()
    assert rows.unsettled.notna().sum() == (~rows.failed).sum()  # every run that ran counts its unsettled frames
    for _, group in rows.groupby(list(KEY_FIELDS)):
        assert group["eval"].tolist() == list(range(12))
    path = write_leaderboard(tmp_path / "runs", tmp_path / "lb")
    for name in LEADERBOARD_FILES:
        assert (tmp_path / "lb" / name).is_file(), name
    assert "Tables 3–4" in path.read_text()
    assert "whose hold ran out before equilibrium" in path.read_text()  # every summary records it
    # a second call finds every cell finished and runs nothing
    again = benchmark([p1], TINY, 2, 12, tmp_path / "runs", workers=2, progress=False)
    assert not again.ran and len(again.skipped) == len(TINY) * 2
    assert len(RunLog(tmp_path / "runs").read(dedupe=False)) == len(rows)


def _csvs(folder: Path) -> dict:
    return {p.name: p.read_text() for p in sorted(folder.glob("*.csv"))}


def test_killed_benchmark_resumes_to_the_same_leaderboard(p1, tmp_path):
    out = tmp_path / "killed"
    args = ["benchmark", "--participants", p1, "--optimizers", *TINY, "--seeds", "2", "--budget", "48"]
    args += ["--out", str(out), "--workers", "1", "--no-progress"]  # one command: killed, then run again
    reference = benchmark([p1], TINY, 2, 48, tmp_path / "reference", workers=1, progress=False)
    assert not reference.failed
    write_leaderboard(tmp_path / "reference", tmp_path / "lb_reference")

    env = dict(os.environ, PYTHONPATH=str(REPO))
    proc = subprocess.Popen(
        [sys.executable, "-m", "wrist_env.cli", *args],
        env=env,
        cwd=tmp_path,
        start_new_session=True,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
    )
    deadline = time.monotonic() + 90
    while time.monotonic() < deadline and proc.poll() is None:
        if list((out / "evals").glob("part-*.parquet")):  # a cell is half done
            break
        time.sleep(0.01)
    assert proc.poll() is None, f"the benchmark ended before it could be killed: {proc.stderr.read()}"
    os.killpg(proc.pid, signal.SIGKILL)
    proc.wait()
    log = RunLog(out)
    logged = sum(log.progress().values())
    assert 0 < logged < len(TINY) * 2 * 48
    assert list((out / "evals").glob("part-*.parquet")), "no cell was left half done"

    assert main([*args, "--leaderboard", str(tmp_path / "lb_resumed")]) == 0
    rows = log.read(dedupe=False)
    assert len(rows) == len(TINY) * 2 * 48 and _duplicates(rows) == 0
    assert sum(s["replayed"] for s in log.summaries()) > 0  # the half-done cell resumed by replay
    assert _csvs(tmp_path / "lb_resumed") == _csvs(tmp_path / "lb_reference")


def test_dask_local_cluster_gives_the_same_costs_as_local(p1, tmp_path):
    distributed = pytest.importorskip("distributed")
    sys_path = os.environ.get("PYTHONPATH")
    os.environ["PYTHONPATH"] = str(REPO)  # the worker processes import this checkout
    try:
        with distributed.LocalCluster(
            n_workers=1, threads_per_worker=1, processes=True, host="127.0.0.1", dashboard_address=None
        ) as cluster:
            report = benchmark(
                [p1], ["random"], [0], 16, tmp_path / "dask", scheduler=cluster.scheduler_address, progress=False
            )
    finally:
        if sys_path is None:
            os.environ.pop("PYTHONPATH", None)
        else:
            os.environ["PYTHONPATH"] = sys_path
    assert not report.failed and len(report.ran) == 1
    local = benchmark([p1], ["random"], [0], 16, tmp_path / "local", workers=1, progress=False)
    assert not local.failed
    on_dask, here = RunLog(tmp_path / "dask").read(), RunLog(tmp_path / "local").read()
    assert len(on_dask) == 16
    np.testing.assert_array_equal(on_dask.cost.to_numpy(), here.cost.to_numpy())


def test_cli_calibrate_json_parses(p1, capsys):
    assert main(["calibrate", p1, "--optimizer", "random", "--budget", "8", "--seed", "0", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["nfev"] == 8 and len(out["history_fun"]) == 8 and out["best_cost"] == min(out["history_fun"])
    assert len(out["design"]) == 27 and all(
        out["design"][f"{n}.injury"] == 1.0 for n in ("SLIL_v", "SLIL_p", "SLIL_d", "RSC", "LRL")
    )
    assert 5 < out["design"]["SLIL_d.stiffness"] < 160  # physical units (N/mm), not normalized
    assert np.isfinite(out["validate"]["cost"]) and out["recovery_z"] > 0
    assert out["calibrate"]["cost"] == pytest.approx(out["best_cost"])


def test_log_refuses_an_evaluation_twice(tmp_path):
    log, key = RunLog(tmp_path), RunKey("P1", "random", 0, 4)
    x, rmse = np.zeros((2, 22)), np.zeros((2, 12))
    log.append(key, 0, 0, x, [1.0, 2.0], [False, False], rmse)
    with pytest.raises(DuplicateEvaluationError):
        log.append(key, 0, 0, x, [1.0, 2.0], [False, False], rmse)
    with pytest.raises(DuplicateEvaluationError):
        log.append(key, 1, 1, x, [1.0, 2.0], [False, False], rmse)  # overlaps evaluation 1
    log.append(key, 1, 2, x, [3.0, 4.0], [False, False], rmse)
    assert log.read()["eval"].tolist() == [0, 1, 2, 3]


class _Unseeded(optimizers.Optimizer):
    """Ignores its seed: cannot be resumed by replay."""

    name = "test-unseeded"

    def _ask(self, n_max):
        return np.random.default_rng().uniform(-0.5, 0.5, (min(n_max, 4), self.dim))

    def _tell(self, x, y):
        pass


def test_a_calibrator_that_ignores_its_seed_cannot_resume(p1, tmp_path, monkeypatch):
    monkeypatch.setitem(optimizers.registry._REGISTRY, _Unseeded.name, _Unseeded)  # registered for this test only

    class Stop(Exception):
        pass

    def stop(n_new, nfev):
        raise Stop

    with pytest.raises(Stop):
        calibrate(p1, "test-unseeded", 8, 0, log=tmp_path, callback=stop)
    with pytest.raises(ResumeError, match="not deterministic"):
        calibrate(p1, "test-unseeded", 8, 0, log=tmp_path)


def test_only_optuna_calibrators_take_a_storage():
    assert not accepts_storage(optimizers.get("random"))
    for name in ("optuna-tpe", "optuna-cmaes"):
        if name in optimizers.available():
            assert accepts_storage(optimizers.get(name))


@pytest.fixture(scope="module")
def finished(p1, tmp_path_factory):
    """A finished tiny benchmark (random, 2 seeds, budget 12, batches of 4 by default) and its leaderboard CSVs."""
    out = tmp_path_factory.mktemp("finished")
    assert not benchmark([p1], ["random"], 2, 12, out / "runs", workers=1, progress=False).failed
    write_leaderboard(out / "runs", out / "lb")
    return out


def _copy_runs(finished, tmp_path) -> Path:
    import shutil

    shutil.copytree(finished / "runs", tmp_path / "runs")
    return tmp_path / "runs"


def test_a_participant_changed_since_its_cells_ran_runs_them_again(p1, finished, tmp_path, monkeypatch):
    """Issue 53: edit a participant's calibrate trial and rerun the same benchmark: its finished cells were
    made on the old trial, so they are moved aside and run again (not "skipped"), and the leaderboard
    refuses the old log against the new trial."""
    from wrist_env.runs import provenance

    runs = _copy_runs(finished, tmp_path)
    today = provenance.of_participant(p1)
    assert RunLog(runs).summary(RunKey(p1, "random", 0, 12))["provenance"] == today
    edited = {**today, "trials": {**today["trials"], "unresisted": "0" * 64}}
    monkeypatch.setattr(provenance, "of_participant", lambda name, instance=0: edited)
    with pytest.raises(StoreError, match=r"seed0.budget12.json: this cell was calibrated on another model or trials"):
        write_leaderboard(runs, tmp_path / "lb")
    with pytest.warns(UserWarning, match=r"made on another model or trials of P1 \(trials unresisted changed\)"):
        report = benchmark([p1], ["random"], 2, 12, runs, workers=1, progress=False)
    assert sorted(k.seed for k in report.ran) == [0, 1] and not report.skipped
    assert all(RunLog(runs).summary(k)["provenance"] == edited for k in report.ran)


def test_a_finished_cell_without_its_evaluations_is_an_error_then_rerun(p1, finished, tmp_path):
    from wrist_env.errors import IncompleteCellError

    runs = _copy_runs(finished, tmp_path)
    evals = sorted((runs / "evals").glob("cell-*seed0*.parquet"))
    assert len(evals) == 1
    evals[0].unlink()
    with pytest.raises(IncompleteCellError, match=r"seed0.*\.json.*12 evaluations, but 0 are logged.*rerun"):
        write_leaderboard(runs, tmp_path / "lb")
    with pytest.warns(UserWarning, match="seed0.*runs again"):
        report = benchmark([p1], ["random"], 2, 12, runs, workers=1, progress=False)
    assert [k.seed for k in report.ran] == [0] and [k.seed for k in report.skipped] == [1]
    write_leaderboard(runs, tmp_path / "lb")
    assert _csvs(tmp_path / "lb") == _csvs(finished / "lb")


@pytest.mark.parametrize("damage", ["truncated", "empty", "garbage"])
def test_a_damaged_evaluation_file_is_named_then_resimulated(p1, finished, tmp_path, damage):
    runs = _copy_runs(finished, tmp_path)
    path = sorted((runs / "evals").glob("cell-*seed1*.parquet"))[0]
    data = path.read_bytes()
    path.write_bytes({"truncated": data[: len(data) // 2], "empty": b"", "garbage": b"garbage" * 50}[damage])
    with pytest.raises(StoreError, match=re.escape(path.name) + ".*damaged Parquet.*rerun the benchmark"):
        write_leaderboard(runs, tmp_path / "lb")
    with pytest.warns(UserWarning, match=re.escape(path.name)):
        report = benchmark([p1], ["random"], 2, 12, runs, workers=1, progress=False)
    assert [k.seed for k in report.ran] == [1] and (runs / "damaged" / path.name).is_file()
    write_leaderboard(runs, tmp_path / "lb")
    assert _csvs(tmp_path / "lb") == _csvs(finished / "lb")


def six_batches_of_an_unfinished_cell(p1, tmp_path):
    """(key, log) of a 12-evaluation Nelder–Mead cell stopped after 6 evaluations, one per batch."""

    class Stop(Exception):
        pass

    def stop_after_six(n_new, nfev):
        if nfev == 6:
            raise Stop

    key, log = RunKey(p1, "nelder-mead", 0, 12), RunLog(tmp_path / "runs")
    with pytest.raises(Stop):  # one evaluation per batch: batches 0 … 5 logged
        calibrate(p1, "nelder-mead", 12, 0, log=log, callback=stop_after_six)
    return key, log


def test_a_damaged_part_of_an_unfinished_cell_drops_it_and_what_follows(p1, tmp_path):
    key, log = six_batches_of_an_unfinished_cell(p1, tmp_path)
    assert log.logged_range(key) == 6
    sorted((tmp_path / "runs" / "evals").glob("part-*b00002*.parquet"))[0].write_bytes(b"")
    with pytest.warns(UserWarning, match="b00002"):
        assert log.repair() == 4  # the damaged batch and the three after it
    assert log.logged_range(key) == 2 and len(list((tmp_path / "runs" / "damaged").glob("*.parquet"))) == 4
    report = benchmark([p1], ["nelder-mead"], [0], 12, tmp_path / "runs", workers=1, progress=False)
    assert report.ran == [key] and log.summary(key)["replayed"] == 2
    reference = benchmark([p1], ["nelder-mead"], [0], 12, tmp_path / "reference", workers=1, progress=False)
    assert not reference.failed
    assert log.read_cell(key).cost.tolist() == RunLog(tmp_path / "reference").read_cell(key).cost.tolist()


def test_a_deleted_middle_part_of_an_unfinished_cell_is_repaired_by_the_rerun(p1, tmp_path):
    key, log = six_batches_of_an_unfinished_cell(p1, tmp_path)
    sorted((tmp_path / "runs" / "evals").glob("part-*b00002*.parquet"))[0].unlink()
    with pytest.warns(UserWarning, match=r"b00003.*evaluations 2…2 of its cell are missing"):
        report = benchmark([p1], ["nelder-mead"], [0], 12, tmp_path / "runs", workers=1, progress=False)
    assert report.ran == [key] and not report.failed and log.summary(key)["replayed"] == 2
    reference = benchmark([p1], ["nelder-mead"], [0], 12, tmp_path / "reference", workers=1, progress=False)
    assert not reference.failed
    assert log.read_cell(key).cost.tolist() == RunLog(tmp_path / "reference").read_cell(key).cost.tolist()


def test_a_truncated_cell_summary_is_named_then_rerun_by_replay(p1, finished, tmp_path):
    runs = _copy_runs(finished, tmp_path)
    path = sorted((runs / "cells").glob("*seed0*.json"))[0]
    path.write_text(path.read_text()[:40])
    with pytest.raises(StoreError, match=re.escape(str(path)) + ".*cannot be read as JSON"):
        write_leaderboard(runs, tmp_path / "lb")
    with pytest.warns(UserWarning, match="cannot be read as JSON"):
        report = benchmark([p1], ["random"], 2, 12, runs, workers=1, progress=False)
    assert [k.seed for k in report.ran] == [0] and RunLog(runs).summary(report.ran[0])["replayed"] == 12


def test_two_benchmarks_on_one_folder_at_once_log_every_evaluation_once(p1, tmp_path):
    args = [
        "--participants",
        p1,
        "--optimizers",
        "random",
        "--seeds",
        "3",
        "--budget",
        "24",
        "--out",
        str(tmp_path / "runs"),
        "--workers",
        "1",
        "--no-progress",
    ]
    env = dict(os.environ, PYTHONPATH=str(REPO))
    procs = [
        subprocess.Popen(
            [sys.executable, "-m", "wrist_env.cli", "benchmark", *args],
            env=env,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.PIPE,
        )
        for _ in range(2)
    ]
    for proc in procs:
        assert proc.wait(timeout=600) == 0, proc.stderr.read().decode()[-2000:]
    log = RunLog(tmp_path / "runs")
    rows = log.read(dedupe=False)
    assert len(rows) == 3 * 24 and _duplicates(rows) == 0 and len(log.summaries()) == 3


def test_a_calibration_on_instance_1_scores_against_instance_1(p1_instance_1, tmp_path):
    """Its cost is instance 1's calibration trial's, its held-out score instance 1's validate trial's, its
    recovery against instance 1's truth; its log and summary say instance 1 and its provenance binds it."""
    from wrist_env import design
    from wrist_env.bench.calibrate import action, recovery_error
    from wrist_env.bench.schema import X_COLUMNS
    from wrist_env.participants import instances
    from wrist_env.runs import provenance
    from wrist_env.task import task

    runs = tmp_path / "runs"
    report = benchmark(["P1"], ["random"], "instance", 8, runs, instances=[0, 1], workers=1, progress=False)
    assert not report.failed and [k.name for k in report.ran] == [
        "P1.random.seed0.budget8",
        "P1.i1.random.seed1.budget8",
    ]
    log, key = RunLog(runs), report.ran[1]
    summary, rows = log.summary(key), log.read_cell(key)
    assert summary["instance"] == 1 and rows.instance.tolist() == [1] * 8
    calibrated = design.Design.from_dict(summary["design"])
    truth = instances.truth("P1", 1)
    assert summary["recovery_z"] == pytest.approx(recovery_error(calibrated, truth), rel=1e-9)
    assert abs(summary["recovery_z"] - recovery_error(calibrated, instances.truth("P1", 0))) > 0.05
    assert summary["recovery_z_population"] == pytest.approx(recovery_error(design.population(), truth), rel=1e-9)
    first = design.from_action(action(rows[list(X_COLUMNS)].to_numpy()[0]))
    on_1, on_0 = (task("P1", "calibrate", instance=k).evaluate(first).cost for k in (1, 0))
    assert rows.cost[0] == pytest.approx(on_1, rel=1e-9) and abs(on_1 - on_0) > 1e-3
    assert summary["validate"]["cost"] == pytest.approx(task("P1", "validate", instance=1).evaluate(calibrated).cost)
    assert summary["provenance"] == provenance.of_participant("P1", 1) != provenance.of_participant("P1", 0)
    # the leaderboard: a row per problem in the CSVs, each with its own references; pooled per participant
    write_leaderboard(runs, tmp_path / "lb")
    best = pd.read_csv(tmp_path / "lb" / "best_cost.csv")
    assert best.participant.tolist() == ["P1", "P1"] and best.instance.tolist() == [0, 1]
    assert best.problem.tolist() == ["P1", "P1.i1"] and best.runs.tolist() == [1, 1]
    pooled = pd.read_csv(tmp_path / "lb" / "evals_to_target.csv")
    assert set(pooled.participant) == {"P1"} and (pooled.runs == 2).all() and (pooled.instances == 2).all()
    population = [task("P1", "calibrate", instance=k).evaluate(design.population()).cost for k in (0, 1)]
    np.testing.assert_allclose(best.population, population, rtol=1e-5)  # each problem's own trial
    assert population[0] != population[1]
    np.testing.assert_allclose(best.truth[1], task("P1", "calibrate", instance=1).evaluate(truth).cost, rtol=1e-5)
    assert pd.read_csv(tmp_path / "lb" / "runs.csv").instance.tolist() == [0, 1]
    # a cell made on instance 1 is not resumed on other trials
    with pytest.warns(UserWarning, match=r"made on another model or trials of P1 instance 1 \(instance 1 \(now 0\)"):
        assert log.move_aside_stale(key, provenance.of_participant("P1", 0)) == 2
