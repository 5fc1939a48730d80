"""The run store: write-once atomic parts, damaged files named, quarantine, locks, temporary files."""

import json
import os
import re
import time

import pyarrow as pa
import pytest

from wrist_env.errors import StoreError
from wrist_env.runs import PartExistsError, RunStore, StoreBusyError
from wrist_env.runs.store import add_checksums

TABLE = pa.table({"x": [1, 2]})


def test_parts_are_written_once_and_read_back_in_name_order(tmp_path):
    store = RunStore(tmp_path, parts="p")
    assert store.read_parts() is None
    store.write_part("b", pa.table({"x": [3]}))
    store.write_part("a", TABLE)
    with pytest.raises(PartExistsError, match="written once"):
        store.write_part("a", TABLE)
    assert store.part_names() == ["a", "b"] and store.read_parts()["x"].to_pylist() == [1, 2, 3]
    with pytest.raises(ValueError, match="plain file name"):
        store.write_part("../escape", TABLE)


@pytest.mark.parametrize("damage", [b"", b"PAR1 garbage", None])
def test_a_damaged_part_is_a_store_error_naming_it(tmp_path, damage):
    store = RunStore(tmp_path, parts="p")
    path = store.write_part("a", TABLE)
    data = path.read_bytes()
    path.write_bytes(data[: len(data) // 2] if damage is None else damage)
    with pytest.raises(StoreError, match=re.escape(str(path)) + ".*damaged Parquet.*do this"):
        store.read_parts(advice="do this")
    assert [name for name, _ in store.damaged_parts()] == ["a"]


def test_records_round_trip_and_a_truncated_record_is_named(tmp_path):
    store = RunStore(tmp_path)
    store.write_record("cell", {"nfev": 3})
    assert store.read_record("cell") == {"nfev": 3} and store.read_record("other") is None
    path = store.record_path("cell")
    path.write_text(path.read_text()[:5])
    with pytest.raises(StoreError, match=re.escape(str(path)) + ".*cannot be read as JSON"):
        store.read_record("cell")


def test_quarantine_moves_the_file_aside_with_a_warning(tmp_path):
    store = RunStore(tmp_path, parts="p")
    path = store.write_part("a", TABLE)
    with pytest.warns(UserWarning, match="a.parquet: broken"):
        target = store.quarantine(path, "broken")
    assert not path.exists() and target == tmp_path / "damaged" / "a.parquet" and target.is_file()
    assert store.quarantine(path, "gone") is None


def test_only_stale_temporary_files_are_cleaned(tmp_path):
    store = RunStore(tmp_path, parts="p")
    store.write_part("a", TABLE)
    stale, live = tmp_path / "p" / ".b.parquet.dead.tmp", tmp_path / "p" / ".c.parquet.live.tmp"
    stale.write_bytes(b"half a file")
    live.write_bytes(b"being written")
    old = time.time() - 3600
    os.utime(stale, (old, old))
    assert store.clean(min_age_s=60) == 1 and not stale.exists() and live.exists()
    assert store.part_names() == ["a"]


def test_a_held_lock_refuses_a_second_holder_that_will_not_wait(tmp_path):
    store = RunStore(tmp_path)
    with store.lock(what="a test study"):
        with pytest.raises(StoreBusyError, match=rf"pid {os.getpid()}\) is running a test study"):
            with RunStore(tmp_path).lock(wait=False, what="a test study"):
                pass
    with RunStore(tmp_path).lock(wait=False):  # released
        pass


def test_a_part_changed_after_it_was_written_fails_its_checksum(tmp_path):
    import pyarrow.parquet as pq

    store = RunStore(tmp_path, parts="p")
    path = store.write_part("a", TABLE)
    assert (tmp_path / "p" / "a.parquet.sha256").is_file()
    pq.write_table(pa.table({"x": [1, 3]}), path)  # a valid file, one value edited
    with pytest.raises(StoreError, match=re.escape(str(path)) + r".*SHA-256.*a.parquet.sha256.*changed.*do this"):
        store.read_parts(advice="do this")
    assert [name for name, _ in store.damaged_parts()] == ["a"]
    with pytest.warns(UserWarning, match="a.parquet"):
        target = store.quarantine(path, "changed")
    assert (tmp_path / "damaged" / "a.parquet.sha256").is_file() and target.is_file()
    store.write_part("a", TABLE)  # written again, with its own checksum
    assert store.read_parts()["x"].to_pylist() == [1, 2]


def test_a_part_without_its_checksum_is_damage_until_checksummed_on_request(tmp_path):
    """Deleting a checksum must not switch checking off; `add_checksums` (for a log made before them)
    names what it checksums, once."""
    store = RunStore(tmp_path, parts="p")
    store.write_part("a", TABLE)
    path = tmp_path / "p" / "a.parquet"
    (tmp_path / "p" / "a.parquet.sha256").unlink()
    with pytest.raises(StoreError, match=re.escape(str(path)) + ": it has no checksum.*wrist-bench checksum"):
        store.read_parts()
    assert [n for n, _ in store.damaged_parts()] == ["a"]
    assert add_checksums(tmp_path) == [path]
    assert store.read_parts()["x"].to_pylist() == [1, 2]
    assert add_checksums(tmp_path) == []  # named once


def test_a_record_without_its_checksum_is_damage_until_checksummed_on_request(tmp_path):
    store = RunStore(tmp_path, records="cells")
    store.write_record("cell", {"nfev": 3, "best_cost": 1.5})
    path = store.record_path("cell")
    path.write_text(json.dumps({"nfev": 3, "best_cost": 0.001}))  # edited, its checksum removed
    with pytest.raises(StoreError, match=re.escape(str(path)) + ": it has no checksum"):
        store.read_record("cell")
    assert add_checksums(tmp_path) == [path]
    assert store.read_record("cell") == {"nfev": 3, "best_cost": 0.001}


def test_add_checksums_refuses_a_damaged_part_and_a_missing_folder(tmp_path):
    store = RunStore(tmp_path, parts="p")
    store.write_part("a", TABLE)
    path = tmp_path / "p" / "a.parquet"
    (tmp_path / "p" / "a.parquet.sha256").unlink()
    path.write_bytes(path.read_bytes()[:40])
    with pytest.raises(StoreError, match=re.escape(str(path)) + ": damaged Parquet"):
        add_checksums(tmp_path)
    with pytest.raises(StoreError, match="no such folder"):
        add_checksums(tmp_path / "nowhere")


def test_a_record_changed_after_it_was_written_fails_its_checksum(tmp_path):
    store = RunStore(tmp_path)
    store.write_record("cell", {"nfev": 3, "best_cost": 1.5})
    path = store.record_path("cell")
    assert store.read_record("cell") == {"nfev": 3, "best_cost": 1.5}
    path.write_text(path.read_text().replace("1.5", "0.5"))
    with pytest.raises(StoreError, match=re.escape(str(path)) + ".*damaged record.*SHA-256.*do this"):
        store.read_record("cell", advice="do this")


def test_the_checksum_of_a_part_never_moved_into_place_is_cleaned(tmp_path):
    store = RunStore(tmp_path, parts="p")
    store.write_part("a", TABLE)
    orphan = tmp_path / "p" / "b.parquet.sha256"  # its writer was killed between the two files
    orphan.write_text("0" * 64)
    assert store.clean(min_age_s=0) == 1 and not orphan.exists()
    assert (tmp_path / "p" / "a.parquet.sha256").is_file()


def test_the_checksum_command_names_each_file_it_checksums_once(tmp_path, capsys):
    from wrist_env import cli

    store = RunStore(tmp_path, parts="p")
    store.write_part("a", TABLE)
    (tmp_path / "p" / "a.parquet.sha256").unlink()
    assert cli.main(["checksum", str(tmp_path)]) == 0
    assert capsys.readouterr().out.splitlines() == [
        f"checksummed {tmp_path / 'p' / 'a.parquet'}",
        f"1 files checksummed in {tmp_path}",
    ]
    assert cli.main(["checksum", str(tmp_path)]) == 0 and "every file has its checksum" in capsys.readouterr().out
    assert cli.main(["checksum", str(tmp_path / "nowhere")]) == 2
    assert capsys.readouterr().err.count("\n") == 1
