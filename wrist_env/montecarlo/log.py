"""An append-only log of Parquet part files: written atomically as chunks finish, read back whole.

`PartLog(root)` is a folder of `<name>.parquet` files. `write(name, table)`
writes to a hidden temporary name in the same folder, fsyncs, and moves it
into place with `os.replace`, so a reader or a killed writer never sees half
a part; a name that exists is never overwritten. `read()` concatenates every
part in name order. Nothing here knows what a row means: the Monte Carlo
study (`wrist_env.montecarlo.study`) names its parts by participant and
sample range and checks that no run is logged twice.

(The calibration benchmark's `wrist_env/bench/log.py` has its own schema-bound
log with the same atomic-replace idea; the two could share this writer.)
"""

from __future__ import annotations

import json
import os
import uuid
from pathlib import Path

import pyarrow as pa
import pyarrow.parquet as pq


class PartExistsError(FileExistsError):
    """A part of that name is already in the log (parts are written once)."""


def atomic_write_bytes(path: Path, write) -> Path:
    """Call `write(tmp_path)`, fsync, then move the file to `path` (same folder, atomic)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.{uuid.uuid4().hex}.tmp")
    try:
        write(tmp)
        with open(tmp, "rb") as handle:
            os.fsync(handle.fileno())
        os.replace(tmp, path)
    finally:
        if tmp.exists():
            tmp.unlink()
    return path


def write_json(path: Path, data) -> Path:
    """Strict JSON (no NaN), atomically."""
    text = json.dumps(data, indent=1, allow_nan=False, sort_keys=True)
    return atomic_write_bytes(path, lambda p: Path(p).write_text(text + "\n"))


class PartLog:
    """Parquet parts under `root` (created on the first write)."""

    def __init__(self, root):
        self.root = Path(root)

    def path(self, name: str) -> Path:
        if not name or "/" in name or name.startswith("."):
            raise ValueError(f"a part name must be a plain file name, but got {name!r}")
        return self.root / f"{name}.parquet"

    def names(self) -> list[str]:
        """The names of the parts written so far, sorted (temporary files are not parts)."""
        if not self.root.is_dir():
            return []
        return sorted(p.name[:-len(".parquet")] for p in self.root.glob("*.parquet") if not p.name.startswith("."))

    def write(self, name: str, table: pa.Table) -> Path:
        """Write one part, atomically and once (`PartExistsError` if `name` is taken)."""
        path = self.path(name)
        if path.exists():
            raise PartExistsError(f"{path} is already in the log")
        return atomic_write_bytes(path, lambda p: pq.write_table(table, p))

    def read(self, schema: pa.Schema | None = None, columns=None) -> pa.Table | None:
        """Every part concatenated in name order, or None if the log is empty."""
        names = self.names()
        if not names:
            return None
        tables = [pq.read_table(self.path(n), schema=schema, columns=columns) for n in names]
        return pa.concat_tables(tables)

    def clean(self) -> int:
        """Remove temporary files a killed writer left behind; returns how many."""
        if not self.root.is_dir():
            return 0
        stale = [p for p in self.root.glob(".*.tmp")]
        for p in stale:
            p.unlink(missing_ok=True)
        return len(stale)
