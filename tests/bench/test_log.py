"""The benchmark's run log without a model: gaps, changed files and incomplete summaries repaired on rerun."""

import json
import re

import numpy as np
import pyarrow.parquet as pq
import pytest

from wrist_env.bench import RunKey, RunLog
from wrist_env.errors import StoreError

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
    with pytest.warns(UserWarning, match="damaged cell summary"):
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
    with pytest.warns(UserWarning, match="damaged cell summary"):
        assert log.repair() == 1


def test_a_compacted_cell_keeps_one_checksummed_file(tmp_path):
    log = _log_batches(tmp_path, 4)
    path = log.compact(KEY)
    assert sorted(p.name for p in log.evals_dir.iterdir()) == [path.name, path.name + ".sha256"]
    assert log.read_cell(KEY).cost.tolist() == list(range(8))
