"""The Monte Carlo study's log without the solver (a stand-in `run_chunk`): settings, copies, gaps, checksums."""

import json
import re
import shutil

import numpy as np
import pyarrow.parquet as pq
import pytest

from wrist_env import cli
from wrist_env.errors import InputError, StoreError
from wrist_env.montecarlo import StudyConfig, StudyError, read_runs, run_study, sampler
from wrist_env.montecarlo.study import config_of, counts
from wrist_env.participants.registry import load_model
from wrist_env.runs import provenance
from wrist_env.runs.store import add_checksums
from wrist_env.solver.settings import DEFAULT_LOADS

CONFIG = StudyConfig(("P1",), n=10, seed=0)


def _fake_chunk(
    participant, sample_ids, blocks, actions, *, exclude_above_mpa=16.5, folders=(), load_direction="axial"
):
    """`sampler.run_chunk`'s rows without simulating: every run ok, its outputs a function of its action."""
    actions = np.asarray(actions, dtype=np.float64)
    k = len(actions)
    table = {
        "participant": [participant] * k,
        "sample_id": np.asarray(sample_ids, dtype=np.int64),
        "block": np.asarray(blocks, dtype=np.int64),
    }
    table.update({n: actions[:, i] for i, n in enumerate(sampler.NAMES)})
    table.update({c: actions[:, 22 + i] < 0 for i, c in enumerate(sampler.TEAR_COLUMNS)})
    for c in sampler.FRAME_COLUMNS:
        table[c] = sampler._frames(np.repeat(actions[:, :1], 3, axis=1))
    table.update({"status": ["ok"] * k, "ok": [True] * k, "excluded": [False] * k})
    import pyarrow as pa

    return pa.Table.from_pydict(table, schema=sampler.SCHEMA)


@pytest.fixture(autouse=True)
def fake_solver(monkeypatch):
    monkeypatch.setattr(sampler, "run_chunk", _fake_chunk)


@pytest.fixture
def study(tmp_path):
    """A finished study of 10 runs in parts of 4, 4 and 2: its folder and log."""
    out = tmp_path / "mc"
    assert run_study(CONFIG, out, batch=4).done
    return out, read_runs(out)


def _cli(capsys, *argv) -> tuple[int, str]:
    status = cli.main(list(argv))
    return status, capsys.readouterr().err


def test_a_resume_with_another_seed_after_study_json_is_deleted_is_refused(study, capsys):
    out, log = study
    (out / "study.json").unlink()
    with pytest.raises(StudyError, match=r"P1-0000000-0000004.parquet: its runs were made with .*seed 0 \(asked 1\)"):
        run_study(StudyConfig(("P1",), n=10, seed=1), out, batch=4)
    status, err = _cli(capsys, "montecarlo", "P1", "--n", "10", "--seed", "1", "--out", str(out), "--no-progress")
    assert status == 2 and err.count("\n") == 1 and "seed 0 (asked 1)" in err
    assert not (out / "study.json").exists() and read_runs(out).equals(log)  # nothing written
    assert run_study(CONFIG, out, batch=4).simulated == 0  # the same settings resume


def test_parts_that_do_not_record_their_settings_need_study_json(study):
    out, _ = study
    for part in (out / "runs").glob("*.parquet"):  # parts as written before they recorded settings
        pq.write_table(pq.read_table(part).replace_schema_metadata(None), part)
        part.with_name(part.name + ".sha256").unlink()
    with pytest.raises(StoreError, match="P1-0000000-0000004.parquet: it has no checksum"):
        read_runs(out)
    assert len(add_checksums(out)) == 3  # the explicit command for a log made before checksums
    with pytest.raises(StudyError, match="P1-0000000-0000004.parquet: its runs were made on another model or trials"):
        run_study(CONFIG, out, batch=4)  # study.json says the settings, but nothing says the model
    (out / "study.json").unlink()
    with pytest.raises(StudyError, match="3 parts .* do not record their settings .* no study.json"):
        run_study(StudyConfig(("P1",), n=10, seed=1), out)


def test_a_copied_part_is_named_then_moved_aside(study):
    out, log = study
    part = sorted((out / "runs").glob("*.parquet"))[1]
    shutil.copy(part, out / "runs" / "P1-copy.parquet")  # with its valid checksum
    shutil.copy(part.with_name(part.name + ".sha256"), out / "runs" / "P1-copy.parquet.sha256")
    with pytest.raises(StudyError, match=r"P1-copy.parquet: run P1 #4 is logged twice \(also in " + part.name):
        read_runs(out)
    with pytest.warns(UserWarning, match="P1-copy.parquet: its runs are not the ones its name says"):
        assert run_study(CONFIG, out, batch=4).simulated == 0
    assert read_runs(out).equals(log) and (out / "damaged" / "P1-copy.parquet").is_file()


def test_a_deleted_part_of_a_finished_study_is_refused_by_the_report_then_resimulated(study, tmp_path, capsys):
    out, log = study
    sorted((out / "runs").glob("*.parquet"))[1].unlink()
    with pytest.raises(StudyError, match=r"not complete: P1 has 6 of 10 successful runs .* \(#4…#7"):
        counts(out, complete=True)
    status, err = _cli(capsys, "montecarlo-report", "--runs", str(out), "--out", str(tmp_path / "report"))
    assert status == 2 and "not complete" in err and not (tmp_path / "report").exists()
    assert run_study(CONFIG, out, batch=4).simulated == 4 and read_runs(out).equals(log)


def test_a_flipped_ok_is_named_then_resimulated(study):
    out, log = study
    part = sorted((out / "runs").glob("*.parquet"))[0]
    table = pq.read_table(part)
    flipped = table.set_column(table.schema.get_field_index("ok"), "ok", pq.read_table(part)["excluded"])
    pq.write_table(flipped, part)  # a valid part, with its metadata, one column changed
    with pytest.raises(StoreError, match=re.escape(part.name) + ".*SHA-256.*rerun the montecarlo command"):
        read_runs(out)
    with pytest.warns(UserWarning, match=re.escape(part.name)):
        assert run_study(CONFIG, out, batch=4).simulated == 4
    assert read_runs(out).equals(log) and (out / "damaged" / part.name).is_file()


def test_sizes_are_refused_before_anything_is_allocated(tmp_path, capsys):
    with pytest.raises(InputError, match=r"n must be an integer in \[1, 1,000,000\].*10000000000"):
        StudyConfig(("P1",), n=10**10)
    with pytest.raises(InputError, match=r"workers must be an integer in \[0, 256\].*-1"):
        run_study(CONFIG, tmp_path, workers=-1)
    with pytest.raises(InputError, match=r"batch must be an integer in \[1, 4,096\]"):
        run_study(CONFIG, tmp_path, batch=10**6)
    for argv, value in (("--n", "10000000000"), ("--workers", "-1"), ("--batch", "0"), ("--seed", "-2")):
        status, err = _cli(capsys, "montecarlo", "P1", argv, value, "--out", str(tmp_path / "x"), "--no-progress")
        assert status == 2 and err.count("\n") == 1 and value in err, (argv, err)
    assert not (tmp_path / "x" / "runs").exists()


def test_a_resume_under_another_load_direction_is_refused(study, tmp_path_factory):
    """The load direction decides every run: a study logged under one load does not resume under the
    other, either way round (a key names the direction only when it is not the axial load, so logs
    from before the tendon lines resume as axial), and the folder's recorded study says which load it ran."""
    out, _ = study
    assert CONFIG.load_direction == DEFAULT_LOADS and CONFIG.key()["load_direction"] == DEFAULT_LOADS
    axial = StudyConfig(("P1",), n=10, seed=0, load_direction="axial")
    assert "load_direction" not in axial.key()
    with pytest.raises(StudyError, match="load_direction"):
        run_study(axial, out, batch=4)
    other = tmp_path_factory.mktemp("axial") / "mc"
    assert run_study(axial, other, batch=4).done
    assert config_of(other).load_direction == "axial"
    with pytest.raises(StudyError, match="load_direction"):
        run_study(CONFIG, other, batch=4)
    with pytest.raises(StudyError, match="sideways"):
        StudyConfig(("P1",), n=10, load_direction="sideways")


def test_the_report_refuses_a_part_copied_from_another_study_with_its_checksum(study, tmp_path, capsys):
    """Issue 53: a part of a seed-1 study (its valid .sha256 beside it) in a seed-0 study's runs/."""
    out, _ = study
    other = tmp_path / "other"
    assert run_study(StudyConfig(("P1",), n=14, seed=1), other, batch=4).done
    part = other / "runs" / "P1-0000012-0000014.parquet"
    for p in (part, part.with_name(part.name + ".sha256")):
        shutil.copy(p, out / "runs" / p.name)
    status, err = _cli(capsys, "montecarlo-report", "--runs", str(out), "--out", str(tmp_path / "report"))
    assert status == 2 and err.count("\n") == 1
    assert "P1-0000012-0000014.parquet: its runs were made with other settings" in err and "seed 1 (asked 0)" in err
    assert not (tmp_path / "report").exists()


def test_the_report_refuses_a_study_json_that_the_parts_contradict(study, tmp_path, capsys):
    out, _ = study
    manifest = json.loads((out / "study.json").read_text())
    (out / "study.json").write_text(json.dumps({**manifest, "seed": 7}))
    status, err = _cli(capsys, "montecarlo-report", "--runs", str(out), "--out", str(tmp_path / "report"))
    assert status == 2 and "P1-0000000-0000004.parquet: its runs were made with other settings" in err
    assert "seed 0 (asked 7)" in err


def test_a_model_changed_between_a_kill_and_a_resume_is_refused(study, monkeypatch):
    """Every part records its participant's model and trials; a resume on another model refuses, naming it."""
    out, log = study
    part = out / "runs" / "P1-0000000-0000004.parquet"
    recorded = provenance.read_provenance(part)
    assert recorded == provenance.of_participant("P1") and recorded["model"] == load_model("P1").source_hash
    changed = {**recorded, "trials": {**recorded["trials"], "unresisted": "0" * 64}}
    monkeypatch.setattr(provenance, "of_participant", lambda name: changed)
    with pytest.raises(
        StudyError, match=re.escape(str(part)) + r": .*another model or trials of P1 \(trials unresisted changed\)"
    ):
        run_study(CONFIG, out, batch=4)
    assert read_runs(out).equals(log)


def test_the_report_refuses_parts_of_one_participant_made_on_two_models(study, tmp_path, capsys):
    out, _ = study
    part = sorted((out / "runs").glob("*.parquet"))[-1]
    table = pq.read_table(part)
    made_from = provenance.read_provenance(part)
    pq.write_table(provenance.with_provenance(table, {**made_from, "model": "f" * 16}), part)
    part.with_name(part.name + ".sha256").unlink()
    add_checksums(out)
    status, err = _cli(capsys, "montecarlo-report", "--runs", str(out), "--out", str(tmp_path / "report"))
    assert (
        status == 2
        and f"{part.name}: made on another model or trials of P1 than" in err
        and "model ffffffffffff…" in err
    )


def test_the_report_of_a_tiny_study_says_how_many_runs_the_fit_needs(tmp_path, capsys):
    """A finished study of 2 runs: the fit's 'singular matrix' traceback became one line naming the folder."""
    out = tmp_path / "tiny"
    assert run_study(StudyConfig(("P1",), n=2, seed=0), out).done
    status, err = _cli(capsys, "montecarlo-report", "--runs", str(out), "--out", str(tmp_path / "report"))
    assert status == 2 and err.count("\n") == 1, err
    assert f"error: {out}: the mixed-effects fit of Table 5 needs at least 7 runs, but the study has 2" in err


def test_the_report_of_a_singular_fit_is_one_line_naming_the_folder(study, tmp_path, capsys):
    """The stand-in solver's outputs are constant within a run: Table 6's fit of its 2 intact runs is singular."""
    out, _ = study
    status, err = _cli(capsys, "montecarlo-report", "--runs", str(out), "--out", str(tmp_path / "report"))
    assert status == 2 and err.count("\n") == 1 and "Traceback" not in err, err
    assert f"{out}: the mixed-effects fit of Table 6 hit a singular matrix" in err and "at least 2 intact runs" in err


def test_ctrl_c_says_how_many_runs_are_kept_and_how_to_resume(tmp_path, capsys, monkeypatch):
    calls = []

    def interrupted_on_the_second_chunk(*args, **kwargs):
        calls.append(1)
        if len(calls) == 2:
            raise KeyboardInterrupt
        return _fake_chunk(*args, **kwargs)

    monkeypatch.setattr(sampler, "run_chunk", interrupted_on_the_second_chunk)
    out = tmp_path / "mc"
    status, err = _cli(capsys, "montecarlo", "P1", "--n", "10", "--batch", "4", "--out", str(out), "--no-progress")
    assert status == 130 and err.count("\n") == 1, err
    assert f"interrupted; 4 runs logged in {out} are kept (every finished batch): rerun the same command" in err
    monkeypatch.setattr(sampler, "run_chunk", _fake_chunk)
    assert run_study(CONFIG, out, batch=4).simulated == 6  # the rerun resumes


def test_a_scheduler_lost_mid_run_says_the_runs_are_kept(tmp_path, capsys, monkeypatch):
    """The scheduler stopped after a part was written (its tasks cancelled): one line, the part kept."""
    from wrist_env.montecarlo import study as study_module
    from wrist_env.runs.executor import Inline, SchedulerError

    class Lost(Inline):
        def results(self, handles, on_poll=None, poll_seconds=0.5):
            for n, item in enumerate(super().results(handles, on_poll, poll_seconds)):
                if n == 1:
                    raise SchedulerError("the dask scheduler tcp://x:1 cancelled a task (FutureCancelledError)")
                yield item

    monkeypatch.setattr(study_module, "executor", lambda *a, **k: Lost())
    out = tmp_path / "mc"
    status, err = _cli(capsys, "montecarlo", "P1", "--n", "10", "--batch", "4", "--out", str(out), "--no-progress")
    assert status == 2 and err.count("\n") == 1, err
    assert "cancelled a task" in err and f"4 runs logged in {out} are kept" in err and "rerun the same command" in err


def test_an_empty_out_is_refused_not_the_current_folder(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    status, err = _cli(capsys, "montecarlo", "P1", "--n", "2", "--out", "", "--no-progress")
    assert status == 2 and err.count("\n") == 1 and "--out is empty" in err, err
    assert list(tmp_path.iterdir()) == []
    with pytest.raises(InputError, match="out is empty"):
        run_study(CONFIG, "")


def test_a_scheduler_with_no_workers_is_one_line_saying_how_to_add_one(tmp_path, capsys, monkeypatch):
    """`montecarlo --scheduler <addr>` on a scheduler without a worker waited forever, silently."""
    import importlib

    distributed = pytest.importorskip("distributed")
    monkeypatch.setattr(importlib.import_module("wrist_env.runs.executor"), "NO_WORKERS_TIMEOUT_S", 0.5)
    out = tmp_path / "mc"
    with distributed.LocalCluster(n_workers=0, processes=False, dashboard_address=None) as cluster:
        address = cluster.scheduler_address
        status, err = _cli(
            capsys, "montecarlo", "P1", "--n", "4", "--scheduler", address, "--out", str(out), "--no-progress"
        )
    assert status == 2 and err.count("\n") == 1, err
    assert re.search(
        rf"the dask scheduler {re.escape(address)} has had no workers for 0\.[5-9] s, so no task can run", err
    )
    assert f"`dask worker {address}`" in err and f"0 runs logged in {out} are kept" in err
