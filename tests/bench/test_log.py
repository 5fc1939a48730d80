"""The benchmark's run log without a model: gaps, changed files and incomplete summaries repaired on rerun."""

import json
import re

import numpy as np
import pyarrow.parquet as pq
import pytest

from wrist_env.bench import RunKey, RunLog
from wrist_env.errors import InputError, StoreError
from wrist_env.runs.store import add_checksums

KEY = RunKey("P1", "random", 0, 8)


def _log_batches(root, n_batches: int, size: int = 2) -> RunLog:
    """A cell cut short after `n_batches` batches of `size` evaluations (costs 0, 1, 2, …)."""
    log = RunLog(root)
    for b in range(n_batches):
        cost = np.arange(b * size, (b + 1) * size, dtype=float)
        log.append(KEY, b, b * size, np.zeros((size, 22)), cost, [False] * size, np.zeros((size, 12)))
    return log


def _summary(nfev: int) -> dict:
    score = {"cost": 1.0, "failed": False, "rmse": [0.0] * 12}
    return {
        **KEY.as_dict(),
        "nfev": nfev,
        "best_cost": 1.0,
        "best_eval": 0,
        "calibrate": score,
        "validate": score,
        "recovery_z": 1.0,
        "recovery_z_population": 2.0,
    }


def test_a_deleted_middle_part_of_an_unfinished_cell_is_repaired(tmp_path):
    log = _log_batches(tmp_path, 4)
    middle = sorted(log.evals_dir.glob("part-*b00001-*.parquet"))[0]
    middle.unlink()
    with pytest.raises(StoreError, match="not 0 … n−1.*rerun the benchmark"):
        log.read_cell(KEY)
    with pytest.warns(UserWarning, match=r"b00002.*evaluations 2…3 of its cell are missing"):
        assert log.repair() == 2  # the batch after the gap and the one after it
    assert log.logged_range(KEY) == 2 and log.read_cell(KEY).cost.tolist() == [0.0, 1.0]
    log.append(KEY, 1, 2, np.zeros((2, 22)), [2.0, 3.0], [False] * 2, np.zeros((2, 12)))  # the rerun goes on
    assert log.read_cell(KEY)["eval"].tolist() == [0, 1, 2, 3]
    assert log.repair() == 0


def test_an_edited_evaluation_is_named_then_moved_aside(tmp_path):
    log = _log_batches(tmp_path, 3)
    path = sorted(log.evals_dir.glob("part-*b00001-*.parquet"))[0]
    table = pq.read_table(path).to_pandas()
    table.loc[0, "cost"] = -1.0  # a better cost, written as a valid Parquet file
    table.to_parquet(path, index=False)
    with pytest.raises(StoreError, match=re.escape(path.name) + ".*SHA-256.*rerun the benchmark"):
        log.read()
    with pytest.warns(UserWarning, match=re.escape(path.name)):
        assert log.repair() == 2
    assert log.logged_range(KEY) == 2 and (tmp_path / "damaged" / path.name).is_file()


def test_a_summary_without_validate_is_named_then_moved_aside(tmp_path):
    log = _log_batches(tmp_path, 4)
    summary = _summary(8)
    del summary["validate"]
    log.write_summary(KEY, summary)
    with pytest.raises(StoreError, match=r"\.json: not a whole cell summary \(no validate\).*rerun the benchmark"):
        log.summaries()
    with pytest.warns(UserWarning, match="not a whole cell summary"):
        assert log.repair() == 1
    assert log.summary(KEY) is None  # the cell runs again, by replay of its 8 logged evaluations


def test_an_edited_summary_is_named_then_moved_aside(tmp_path):
    log = _log_batches(tmp_path, 4)
    path = log.write_summary(KEY, _summary(8))
    assert log.summary(KEY)["best_cost"] == 1.0
    data = json.loads(path.read_text())
    data["best_cost"] = 0.001  # below its own log's minimum
    path.write_text(json.dumps(data))
    with pytest.raises(StoreError, match=re.escape(str(path)) + ".*SHA-256.*rerun the benchmark"):
        log.summaries()
    with pytest.warns(UserWarning, match="damaged record"):
        assert log.repair() == 1


def test_a_compacted_cell_keeps_one_checksummed_file(tmp_path):
    log = _log_batches(tmp_path, 4)
    path = log.compact(KEY)
    assert sorted(p.name for p in log.evals_dir.iterdir()) == [path.name, path.name + ".sha256"]
    assert log.read_cell(KEY).cost.tolist() == list(range(8))


MADE_FROM = {"model": "a" * 16, "trials": {"resisted": "b" * 64, "unresisted": "c" * 64}}


def _finished_cell(root, made_from: dict | None = MADE_FROM) -> RunLog:
    """KEY finished: 4 evaluations in two batches, compacted, and its summary, made on `made_from`."""
    log = RunLog(root)
    for b in range(2):
        cost = [2.0 * b, 2.0 * b + 1]
        log.append(KEY, b, 2 * b, np.zeros((2, 22)), cost, [False] * 2, np.zeros((2, 12)), made_from=made_from)
    log.compact(KEY)
    log.write_summary(KEY, _summary(4), made_from)
    return log


def test_a_cell_copied_under_another_cells_name_is_named_then_moved_aside(tmp_path):
    """Issue 53: P1's finished cell and its evaluations (with their checksums) copied to P2's names must not
    count as P2's run, nor make `benchmark` skip P2."""
    log = _finished_cell(tmp_path)
    other = RunKey("P2", "random", 0, 8)
    for path in [*log.evals_dir.iterdir(), log.store.record_path(KEY.name)]:
        (path.parent / path.name.replace(KEY.name, other.name)).write_bytes(path.read_bytes())
    summary = log.store.record_path(other.name)
    with pytest.raises(StoreError, match=re.escape(str(summary)) + f": holds the summary of cell {KEY.name}, not of"):
        log.summary(other)
    with pytest.warns(UserWarning, match=f"holds evaluations of {re.escape(KEY.name)}, not of {re.escape(other.name)}"):
        assert log.repair() == 2  # the evaluations and the summary under P2's name
    assert log.logged_range(other) == 0 and log.summary(other) is None and log.summary(KEY)["nfev"] == 4


def test_a_summary_whose_checksum_was_removed_is_damage(tmp_path):
    log = _finished_cell(tmp_path)
    path = log.store.record_path(KEY.name)
    data = json.loads(path.read_text())
    del data["record_sha256"]
    path.write_text(json.dumps({**data, "best_cost": 0.001}))
    with pytest.raises(StoreError, match=re.escape(str(path)) + ": it has no checksum"):
        log.summary(KEY)
    with pytest.warns(UserWarning, match="it has no checksum"):
        assert log.repair() == 1
    assert log.summary(KEY) is None


def test_every_file_of_a_cell_records_its_provenance_and_a_stale_cell_moves_aside_whole(tmp_path):
    from wrist_env.runs import provenance

    log = _finished_cell(tmp_path)
    (part,) = log.evals_dir.glob("cell-*.parquet")
    assert provenance.read_provenance(part) == MADE_FROM  # kept through compaction
    assert log.summary(KEY)["provenance"] == MADE_FROM
    assert log.move_aside_stale(KEY, MADE_FROM) == 0
    log.check_made_from({("P1", 0): MADE_FROM})
    edited = {**MADE_FROM, "trials": {**MADE_FROM["trials"], "unresisted": "d" * 64}}
    with pytest.raises(
        StoreError, match=r"this cell was calibrated on another model or trials of P1 \(trials unresisted"
    ):
        log.check_made_from({("P1", 0): edited})
    with pytest.warns(UserWarning, match=r"made on another model or trials of P1 \(trials unresisted changed\)"):
        assert log.move_aside_stale(KEY, edited) == 2
    assert log.logged_range(KEY) == 0 and log.summary(KEY) is None


def test_a_cell_that_records_no_provenance_runs_again(tmp_path):
    log = _finished_cell(tmp_path, made_from=None)
    with pytest.warns(UserWarning, match="does not record the model and trials"):
        assert log.move_aside_stale(KEY, MADE_FROM) == 2


def test_a_cell_on_instance_0_keeps_its_name_and_another_instance_is_named():
    """Instance 0's names are those of logs and Optuna studies made before instances."""
    assert RunKey("P1", "cmaes", 3, 300).name == "P1.cmaes.seed3.budget300"
    assert RunKey("P1", "cmaes", 3, 300, 0).name == "P1.cmaes.seed3.budget300"
    assert RunKey("P1", "cmaes", 3, 300, instance=3).name == "P1.i3.cmaes.seed3.budget300"
    assert RunKey("P2", "ng-ngopt+prior", 0, 8, 12).name == "P2.i12.ng-ngopt+prior.seed0.budget8"
    assert RunKey("P1", "cmaes", 3, 300, 3) != RunKey("P1", "cmaes", 3, 300)


@pytest.mark.parametrize("bad", [-1, 10_001, 1.5, True])
def test_a_bad_instance_is_refused_naming_it(bad):
    with pytest.raises(InputError, match=rf"instance must be an integer in \[0, 10,000\], but got {bad!r}"):
        RunKey("P1", "random", 0, 8, bad)


def _without_instance_column(log: RunLog) -> None:
    """Rewrite every Parquet file of `log` as a log written before instances: no `instance` column."""
    for path in log.evals_dir.glob("*.parquet"):
        table = pq.read_table(path)
        pq.write_table(table.drop_columns(["instance"]), path)
        path.with_name(path.name + ".sha256").unlink()
    add_checksums(log.root)


def test_a_log_written_before_instances_reads_as_instance_0(tmp_path):
    log = _log_batches(tmp_path, 4)
    log.write_summary(KEY, {k: v for k, v in _summary(8).items() if k != "instance"})
    _without_instance_column(log)
    assert "instance" not in pq.read_schema(next(log.evals_dir.glob("*.parquet"))).names
    rows = log.read()
    assert rows.instance.tolist() == [0] * 8 and rows.instance.dtype == np.int64
    assert log.read_cell(KEY).cost.tolist() == list(range(8))
    assert log.repair() == 0  # its files hold the cell their names say
    assert log.summary(KEY)["nfev"] == 8 and "instance" not in log.summary(KEY)
    log.compact(KEY)  # the compacted file has the column
    assert pq.read_table(next(log.evals_dir.glob("cell-*.parquet"))).column("instance").to_pylist() == [0] * 8


def test_cells_of_two_instances_are_two_cells(tmp_path):
    log = _log_batches(tmp_path, 2)
    other = RunKey("P1", "random", 0, 8, instance=2)
    log.append(other, 0, 0, np.ones((3, 22)), [5.0, 6.0, 7.0], [False] * 3, np.zeros((3, 12)))
    assert log.logged_range(KEY) == 4 and log.logged_range(other) == 3
    assert log.read_cell(other).cost.tolist() == [5.0, 6.0, 7.0]
    assert sorted(log.read().groupby("instance").size().items()) == [(0, 4), (2, 3)]
    summary = {**_summary(3), "instance": 2}
    log.write_summary(other, summary)
    assert log.summary(other)["instance"] == 2 and log.summary(KEY) is None


def test_a_cell_made_on_another_instance_moves_aside_and_the_leaderboard_refuses_it(tmp_path):
    log = _finished_cell(tmp_path)  # instance 0's provenance records no instance
    on_instance_1 = {**MADE_FROM, "instance": 1}
    with pytest.raises(StoreError, match=r"calibrated on another model or trials of P1 \(instance 0 \(now 1\)\)"):
        log.check_made_from({("P1", 0): on_instance_1})
    log.check_made_from({("P1", 1): on_instance_1})  # not this cell's problem: nothing to compare
    with pytest.warns(UserWarning, match=r"made on another model or trials of P1 \(instance 0 \(now 1\)\)"):
        assert log.move_aside_stale(KEY, on_instance_1) == 2
