"""The run store both studies log to: write-once Parquet parts, JSON records, locks, damage checks.

A `RunStore(root, parts=...)` is a folder::

    root/<parts>/<name>.parquet   write-once parts (one batch of evaluations, one chunk of runs)
    root/<parts>/<name>.parquet.sha256   the part's SHA-256, written just before it
    root/<records>/<name>.json    JSON records (a finished benchmark cell's summary; its SHA-256 inside)
    root/locks/<name>.lock        flocks: a key's lock while a process runs it, "store" for a whole study
    root/damaged/                 files moved aside by `quarantine` (never deleted)

Every file is written by `wrist_env.io.atomic_write` (temporary name, fsync,
`os.replace`, folder fsync): a reader, or a writer killed midway, never sees
half a file. A part name that exists is never overwritten. Every part and
record carries a SHA-256 (a part's in `<file>.sha256`, a record's under
`record_sha256`), checked on every read. A damaged part or record (truncated, empty,
garbage, not the bytes it was written with, or without its checksum: a deleted
checksum must not switch checking off) is a `StoreError` naming the file and
what to do; the studies move such files to `damaged/` on resume and redo their
work. A log written before checksums existed is checksummed once, on request,
by `add_checksums` (`wrist-bench checksum <folder>`), which names each file.
Nothing here knows what a row means: `wrist_env.bench.log` (the benchmark's
evaluations) and `wrist_env.montecarlo.log` (the Monte Carlo runs) do.
"""

from __future__ import annotations

import fcntl
import os
import shutil
import time
import warnings
from collections.abc import Iterable, Iterator
from contextlib import contextmanager
from pathlib import Path

import pyarrow as pa
import pyarrow.parquet as pq

from wrist_env.errors import StoreError
from wrist_env.io import atomic_write, clean_temporary, json_sha256, read_json, sha256_file, write_json

CHECKSUM = ".sha256"
RECORD_CHECKSUM = "record_sha256"
DAMAGED = "damaged"
LOCKS = "locks"
STORE_LOCK = "store"
RECORD_FOLDERS = ("cells",)
"""The folders whose JSON files are checksummed records (a benchmark's cell summaries); `add_checksums`
leaves other JSON (a study's manifest, a report's summary) alone."""


class PartExistsError(StoreError, FileExistsError):
    """A part of that name is already in the store (parts are written once).

    Raised by `RunStore.write_part`; a `StoreError` and a `FileExistsError`.
    """


class StoreBusyError(StoreError):
    """Another process holds a lock this one was not allowed to wait for.

    Raised by `RunStore.lock` when told not to wait, e.g. for a second Monte Carlo study started on a folder
    while one runs there; the message names the holder.
    """


def checksum_path(path: str | Path) -> Path:
    """Where a Parquet file's SHA-256 is kept: `<file>.sha256` beside it."""
    path = Path(path)
    return path.with_name(path.name + CHECKSUM)


def write_parquet(path: str | Path, table: pa.Table) -> Path:
    """Write a Parquet file atomically, its SHA-256 (`checksum_path`) moved into place just before it."""

    def write(tmp: Path) -> None:
        pq.write_table(table, tmp)
        digest = sha256_file(tmp) + "\n"
        atomic_write(checksum_path(path), lambda c: Path(c).write_text(digest))

    return atomic_write(path, write)


def remove_file(path: str | Path) -> None:
    """Remove a Parquet file and its SHA-256 (either may be gone already)."""
    Path(path).unlink(missing_ok=True)
    checksum_path(path).unlink(missing_ok=True)


def _advice(advice: str) -> str:
    return f"; {advice}" if advice else ""


MISSING = "it has no checksum (deleted, or written before wrist-env kept them: if you trust it, `wrist-bench checksum <folder>` adds them)"
"""Why a part or record without its checksum is refused."""


def verify_checksum(path: str | Path, advice: str = "") -> None:
    """`StoreError` naming `path` if its bytes are not the ones its `.sha256` was written with, or it has
    no `.sha256`."""
    path, side = Path(path), checksum_path(path)
    try:
        expected = side.read_text().strip()
    except FileNotFoundError:
        raise StoreError(f"{path}: {MISSING}{_advice(advice)}") from None
    except (OSError, UnicodeDecodeError) as e:
        raise StoreError(f"{side}: unreadable checksum ({type(e).__name__}){_advice(advice)}") from None
    try:
        actual = sha256_file(path)
    except OSError as e:
        raise StoreError(f"{path}: cannot be read ({type(e).__name__}: {e}){_advice(advice)}") from None
    if actual != expected:
        raise StoreError(
            f"{path}: damaged Parquet file (its SHA-256 {actual[:12]}… is not the {expected[:12]}… of "
            f"{side.name}: changed since it was written){_advice(advice)}"
        )


def read_parquet(
    path: str | Path, schema: pa.Schema | None = None, columns: list[str] | None = None, advice: str = ""
) -> pa.Table:
    """One Parquet file; `StoreError` naming it (and `advice`) if it is truncated, empty, not Parquet
    or not the bytes it was written with."""
    verify_checksum(path, advice)
    try:
        return pq.read_table(path, schema=schema, columns=columns)
    except (OSError, pa.ArrowException, ValueError) as e:
        raise StoreError(
            f"{path}: damaged Parquet file ({type(e).__name__}: {str(e).splitlines()[0][:200]}){_advice(advice)}"
        ) from None


def add_checksums(root: str | Path) -> list[Path]:
    """Checksum the parts and records under `root` that have none (a log written before wrist-env kept
    checksums): each Parquet file without its `.sha256` that reads whole gets one, each JSON record (a
    dict) without `record_sha256` gets it. Returns the files checksummed, for the caller to name: only
    for logs you trust, as a deleted checksum looks the same. `StoreError` naming a file that cannot be
    read whole (it stays unchecked, and a study moves it aside)."""
    root, done = Path(root), []
    if not root.is_dir():
        raise StoreError(f"{root}: no such folder (a benchmark's --out, or a Monte Carlo study's)")
    for path in sorted(root.rglob("*.parquet")):
        if path.name.startswith(".") or DAMAGED in path.relative_to(root).parts or checksum_path(path).exists():
            continue
        try:
            pq.read_table(path)
        except (OSError, pa.ArrowException, ValueError) as e:
            raise StoreError(f"{path}: damaged Parquet file ({type(e).__name__}); not checksummed") from None
        digest = sha256_file(path) + "\n"
        atomic_write(checksum_path(path), lambda c, d=digest: Path(c).write_text(d))
        done.append(path)
    for path in sorted(root.rglob("*.json")):
        if path.name.startswith(".") or DAMAGED in path.relative_to(root).parts:
            continue
        data = read_json(path, "record")
        if isinstance(data, dict) and path.parent.name in RECORD_FOLDERS and RECORD_CHECKSUM not in data:
            write_json(path, {**data, RECORD_CHECKSUM: json_sha256(data)})
            done.append(path)
    return done


class RunStore:
    """Parts, records and locks under `root` (folders created on the first write).

    The layout of the folder and the rules it keeps are the module's docstring.

    Parameters
    ----------
    root : str or Path
        The store's folder.
    parts : str, default "parts"
        The folder of the write-once Parquet parts, under `root`.
    records : str, default "records"
        The folder of the JSON records, under `root`.

    Attributes
    ----------
    root, parts_dir, records_dir, locks_dir, damaged_dir : Path
        The store's folder, and under it the parts, the records, the locks (``locks/``) and the files moved
        aside (``damaged/``).
    """

    def __init__(self, root, *, parts: str = "parts", records: str = "records"):
        self.root = Path(root)
        self.parts_dir = self.root / parts
        self.records_dir = self.root / records
        self.locks_dir = self.root / LOCKS
        self.damaged_dir = self.root / DAMAGED

    # parts

    def part_path(self, name: str) -> Path:
        if not name or "/" in name or name.startswith("."):
            raise ValueError(f"a part name must be a plain file name, but got {name!r}")
        return self.parts_dir / f"{name}.parquet"

    def part_names(self) -> list[str]:
        """The parts written so far, sorted by name (temporary files are not parts)."""
        if not self.parts_dir.is_dir():
            return []
        return sorted(
            p.name[: -len(".parquet")] for p in self.parts_dir.glob("*.parquet") if not p.name.startswith(".")
        )

    def write_part(self, name: str, table: pa.Table) -> Path:
        """Write one part, atomically and once (`PartExistsError` if `name` is taken)."""
        path = self.part_path(name)
        if path.exists():
            raise PartExistsError(f"{path} is already in the store (parts are written once)")
        return write_parquet(path, table)

    def read_part(
        self, name: str, schema: pa.Schema | None = None, columns: list[str] | None = None, advice: str = ""
    ) -> pa.Table:
        return read_parquet(self.part_path(name), schema, columns, advice)

    def read_parts(
        self,
        names: Iterable[str] | None = None,
        schema: pa.Schema | None = None,
        columns: list[str] | None = None,
        advice: str = "",
    ) -> pa.Table | None:
        """The parts `names` (default all) concatenated in name order, or None if there are none."""
        names = self.part_names() if names is None else list(names)
        if not names:
            return None
        return pa.concat_tables([self.read_part(n, schema, columns, advice) for n in names])

    def damaged_parts(self, schema: pa.Schema | None = None) -> list[tuple[str, str]]:
        """(name, error) of every part that cannot be read whole against `schema`."""
        out = []
        for name in self.part_names():
            try:
                self.read_part(name, schema)
            except StoreError as e:
                if self.part_path(name).exists():  # not removed meanwhile by a concurrent compaction
                    out.append((name, str(e)))
        return out

    # records

    def record_path(self, name: str) -> Path:
        if not name or "/" in name or name.startswith("."):
            raise ValueError(f"a record name must be a plain file name, but got {name!r}")
        return self.records_dir / f"{name}.json"

    def write_record(self, name: str, data: object) -> Path:
        """Write a record (a dict gets its SHA-256 under `record_sha256`)."""
        if isinstance(data, dict):
            data = {**data, RECORD_CHECKSUM: json_sha256(data)}
        return write_json(self.record_path(name), data)

    def read_record(self, name: str, advice: str = "") -> dict | list | None:
        """The record `name` (its checksum checked and dropped), or None if there is none; `StoreError`
        naming it if it is damaged or not what was written."""
        path = self.record_path(name)
        if not path.is_file():
            return None
        data = read_json(path, "record", advice)
        if not isinstance(data, dict) or RECORD_CHECKSUM not in data:
            raise StoreError(f"{path}: {MISSING}{_advice(advice)}")
        if isinstance(data, dict):
            expected = data.pop(RECORD_CHECKSUM)
            if json_sha256(data) != expected:
                raise StoreError(
                    f"{path}: damaged record (its SHA-256 is not the {str(expected)[:12]}… it was written "
                    f"with: changed since){_advice(advice)}"
                )
        return data

    def record_names(self) -> list[str]:
        if not self.records_dir.is_dir():
            return []
        return sorted(p.stem for p in self.records_dir.glob("*.json") if not p.name.startswith("."))

    # repair

    def quarantine(self, path: str | Path, reason: str) -> Path | None:
        """Move a damaged or orphaned file to `damaged/` (kept for inspection) with a warning naming it
        (None if it is already gone)."""
        path = Path(path)
        if not path.exists():
            return None
        self.damaged_dir.mkdir(parents=True, exist_ok=True)
        target = self.damaged_dir / path.name
        k = 1
        while target.exists():
            target, k = self.damaged_dir / f"{path.name}.{k}", k + 1
        shutil.move(str(path), target)
        if checksum_path(path).exists():
            shutil.move(str(checksum_path(path)), checksum_path(target))
        warnings.warn(f"{path}: {reason}; moved to {target}", stacklevel=2)
        return target

    def clean(self, min_age_s: float = 60.0) -> int:
        """Remove temporary files killed writers left behind (at least `min_age_s` old, so a concurrent
        writer's file is spared); returns how many."""
        temporary = sum(clean_temporary(d, min_age_s) for d in (self.parts_dir, self.records_dir, self.root))
        return temporary + self._clean_checksums(min_age_s)

    def _clean_checksums(self, min_age_s: float) -> int:
        """Remove the checksums of parts never moved into place (a writer killed between the two)."""
        if not self.parts_dir.is_dir():
            return 0
        now, removed = time.time(), 0
        for side in self.parts_dir.glob(f"*{CHECKSUM}"):
            try:
                if not side.with_name(side.name[: -len(CHECKSUM)]).exists() and now - side.stat().st_mtime >= min_age_s:
                    side.unlink()
                    removed += 1
            except FileNotFoundError:
                pass
        return removed

    # locks

    @contextmanager
    def lock(self, name: str = STORE_LOCK, *, wait: bool = True, what: str = "this run store") -> Iterator[None]:
        """Hold the flock `locks/<name>.lock` (released when the process dies, even by SIGKILL).

        wait=False: `StoreBusyError` naming the holder's process id if another process holds it.
        """
        self.locks_dir.mkdir(parents=True, exist_ok=True)
        path = self.locks_dir / f"{name}.lock"
        with open(path, "a+") as handle:
            try:
                fcntl.flock(handle, fcntl.LOCK_EX | (0 if wait else fcntl.LOCK_NB))
            except BlockingIOError:
                handle.seek(0)
                holder = handle.read().strip() or "?"
                raise StoreBusyError(
                    f"{path}: another process (pid {holder}) is running {what}; wait for it to "
                    f"finish or stop it (a killed run releases the lock)"
                ) from None
            handle.seek(0)
            handle.truncate()
            handle.write(str(os.getpid()))
            handle.flush()
            try:
                yield
            finally:
                handle.truncate(0)
                fcntl.flock(handle, fcntl.LOCK_UN)
