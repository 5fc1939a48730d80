"""Save and load frozen dataclasses of arrays as `.npz` + `.json` (never pickle).

Array fields (and tuples of arrays) go to the `.npz`; everything else must be
JSON-able and goes to the `.json`, with the class name, a format version and
the SHA-256 of the `.npz`. Both are written to a temporary name and moved into
place, the `.npz` first, so a reader sees a whole pair or no `.json`; a load
checks the hash and the fields and raises `StoreError` naming the file; so do it and `read_json`
for a path that is not a regular file (a link to /dev/zero, a FIFO: reading it would never end).
`fields_equal` is such a dataclass's `__eq__` (arrays compared by value).
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import os
import stat
import time
import uuid
import zipfile
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, TypeVar

import numpy as np

from wrist_env.errors import InputError, StoreError

if TYPE_CHECKING:
    from _typeshed import DataclassInstance

__all__ = [
    "FORMAT_VERSION",
    "save_dataclass",
    "load_dataclass",
    "fields_equal",
    "check_regular",
    "sha256_file",
    "atomic_write",
    "clean_temporary",
    "write_json",
    "json_sha256",
    "read_json",
]

_D = TypeVar("_D", bound="DataclassInstance")

FORMAT_VERSION = 1


def save_dataclass(obj: DataclassInstance, path: str | Path) -> None:
    """Write `path.npz` and `path.json` for a frozen dataclass.

    Parameters
    ----------
    obj : dataclass
        The frozen dataclass: its array fields go to the `.npz`, the others (JSON-able) to the `.json`.
    path : str or Path
        The pair's path; its suffix is replaced by `.npz` and `.json`.
    """
    path = Path(path)
    arrays, meta = {}, {}
    for f in dataclasses.fields(obj):
        value = getattr(obj, f.name)
        if isinstance(value, np.ndarray):
            arrays[f.name] = value
        else:
            meta[f.name] = value
    path.parent.mkdir(parents=True, exist_ok=True)
    digest = {}

    def write_npz(tmp: Path) -> None:
        with open(tmp, "wb") as fh:
            np.savez_compressed(fh, **arrays)
        digest["sha256"] = sha256_file(tmp)

    atomic_write(path.with_suffix(".npz"), write_npz)
    header = {"class": type(obj).__name__, "format": FORMAT_VERSION, "npz_sha256": digest["sha256"], "fields": meta}
    text = json.dumps(header, indent=1, default=_jsonable)
    atomic_write(path.with_suffix(".json"), lambda p: Path(p).write_text(text))


def load_dataclass(cls: type[_D], path: str | Path) -> _D:
    """Read an instance of the dataclass `cls` written by `save_dataclass`.

    Parameters
    ----------
    path : str or Path
        The pair's path; its suffix is replaced by `.npz` and `.json`.

    Returns
    -------
    object
        The instance of `cls`.

    Raises
    ------
    StoreError
        The pair is damaged, its `.npz` is not the one the `.json` was written with, or a field is missing
        (the message names the file).
    """
    path = Path(path)
    js, npz = path.with_suffix(".json"), path.with_suffix(".npz")
    for p in (js, npz):
        check_regular(p, "delete it to rebuild")
    try:
        header = json.loads(js.read_text())
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as e:
        raise StoreError(f"{js}: cannot be read as JSON ({e}); delete it to rebuild") from None
    if not isinstance(header, dict) or header.get("class") != cls.__name__ or header.get("format") != FORMAT_VERSION:
        raise StoreError(
            f"{js} holds {header.get('class') if isinstance(header, dict) else header!r} "
            f"v{header.get('format') if isinstance(header, dict) else '?'}, not {cls.__name__} v{FORMAT_VERSION}"
        )
    try:
        digest = sha256_file(npz)
    except OSError as e:
        raise StoreError(f"{npz}: cannot be read ({e}); delete {js} to rebuild") from None
    if header.get("npz_sha256") != digest:
        raise StoreError(
            f"{npz}: its SHA-256 {digest[:12]}… is not the {str(header.get('npz_sha256'))[:12]}… "
            f"written with {js.name} (damaged or changed); delete both to rebuild"
        )
    try:
        with np.load(npz, allow_pickle=False) as data:
            arrays = {k: data[k] for k in data.files}
    except (OSError, ValueError, zipfile.BadZipFile, EOFError) as e:
        raise StoreError(f"{npz}: cannot be read ({e}); delete it to rebuild") from None
    kwargs = {**header.get("fields", {}), **arrays}
    missing = [
        f.name
        for f in dataclasses.fields(cls)
        if f.name not in kwargs and f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING
    ]
    if missing:
        raise StoreError(f"{path}: lacks fields {missing} of {cls.__name__}; delete it to rebuild")
    for f in dataclasses.fields(cls):
        if isinstance(kwargs.get(f.name), list) and str(f.type).startswith("tuple"):
            kwargs[f.name] = tuple(kwargs[f.name])
    try:
        return cls(**{f.name: kwargs[f.name] for f in dataclasses.fields(cls) if f.name in kwargs})
    except StoreError:
        raise
    except InputError as e:  # a field of another layout (e.g. a model of another body count)
        raise StoreError(f"{path}: {e}; delete it to rebuild") from None


def fields_equal(a: DataclassInstance, b: DataclassInstance, scalars: tuple[str, ...], arrays: tuple[str, ...]) -> bool:
    """Whether two dataclasses agree on their scalar and array fields.

    The `__eq__` of a frozen dataclass of arrays (declared with eq=False: the generated one would compare
    arrays elementwise).

    Parameters
    ----------
    a, b : dataclass
        The two instances.
    scalars : tuple of str
        The fields compared with ==.
    arrays : tuple of str
        The fields compared with `np.array_equal`.

    Returns
    -------
    bool
        Whether every field listed is equal.
    """
    return all(getattr(a, k) == getattr(b, k) for k in scalars) and all(
        np.array_equal(getattr(a, k), getattr(b, k)) for k in arrays
    )


def check_regular(path: str | Path, advice: str = "", what: str = "file") -> None:
    """Check that a path, if it exists, is a regular file (after symbolic links).

    A device such as /dev/zero, a FIFO or a socket would make a read hang or never end. A missing path
    passes (the read that follows names it).

    Parameters
    ----------
    path : str or Path
        The path about to be read.
    advice : str, default ""
        What to do about it, appended to the message.
    what : str, default "file"
        What the file is, as the message names it.

    Raises
    ------
    StoreError
        It exists but is not a regular file (the message names `path` and `advice`).
    """
    try:
        mode = os.stat(path).st_mode
    except OSError:
        return
    if not stat.S_ISREG(mode):
        kind = _KINDS.get(stat.S_IFMT(mode), "special file")
        raise StoreError(
            f"{path}: this {what} is a {kind}, not a regular file, so it is not read"
            + (f"; {advice}" if advice else "")
        )


_KINDS = {
    stat.S_IFDIR: "folder",
    stat.S_IFCHR: "character device",
    stat.S_IFBLK: "block device",
    stat.S_IFIFO: "FIFO (named pipe)",
    stat.S_IFSOCK: "socket",
}


def sha256_file(path: str | Path) -> str:
    """The SHA-256 of a file's bytes.

    Parameters
    ----------
    path : str or Path
        The file.

    Returns
    -------
    str
        The digest, hex.
    """
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def _fsync(path: Path) -> None:
    with open(path, "rb+") as fh:
        os.fsync(fh.fileno())


def _fsync_dir(folder: Path) -> None:
    """Make a rename in `folder` durable (a no-op where directories cannot be opened)."""
    try:
        fd = os.open(folder, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


def atomic_write(path: str | Path, write: Callable[[Path], object]) -> Path:
    """Write a file whole or not at all.

    `write(tmp_path)` to a hidden name in the same folder, fsync, `os.replace` onto `path`, fsync the
    folder. A reader, or a writer killed midway, never sees half a file; a killed writer leaves at most a
    `.<name>.<hex>.tmp` (`clean_temporary`).

    Parameters
    ----------
    path : str or Path
        The file written.
    write : callable
        ``write(tmp_path)`` writes the file's content to the temporary path it is given.

    Returns
    -------
    Path
        `path`.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.{uuid.uuid4().hex}.tmp")
    try:
        write(tmp)
        _fsync(tmp)
        os.replace(tmp, path)
        _fsync_dir(path.parent)
    finally:
        if tmp.exists():
            tmp.unlink()
    return path


def clean_temporary(folder: str | Path, min_age_s: float = 0.0) -> int:
    """Remove the temporary files left in a folder by killed `atomic_write` calls.

    Parameters
    ----------
    folder : str or Path
        The folder (a missing one has none).
    min_age_s : float, default 0.0
        The youngest file removed, s: a live writer's file is younger.

    Returns
    -------
    int
        How many files were removed.
    """
    folder = Path(folder)
    if not folder.is_dir():
        return 0
    now, removed = time.time(), 0
    for p in folder.glob(".*.tmp"):
        try:
            if now - p.stat().st_mtime >= min_age_s:
                p.unlink()
                removed += 1
        except FileNotFoundError:
            pass
    return removed


def write_json(path: str | Path, data: object) -> Path:
    """Write strict JSON (no NaN; sorted keys), atomically (`atomic_write`).

    Parameters
    ----------
    path : str or Path
        The file written.
    data : object
        JSON-able data (NumPy scalars, arrays and tuples are written as numbers and lists).

    Returns
    -------
    Path
        `path`.
    """
    text = json.dumps(data, indent=1, allow_nan=False, sort_keys=True, default=_jsonable) + "\n"
    return atomic_write(path, lambda p: Path(p).write_text(text))


def json_sha256(data: object) -> str:
    """The SHA-256 of data as canonical JSON (sorted keys, no spaces).

    Equal for a dict and the same dict written by `write_json` and read back.

    Parameters
    ----------
    data : object
        JSON-able data, as `write_json` takes.

    Returns
    -------
    str
        The digest, hex.
    """
    text = json.dumps(data, sort_keys=True, allow_nan=False, separators=(",", ":"), default=_jsonable)
    return hashlib.sha256(text.encode("utf-8")).hexdigest()


def read_json(path: str | Path, what: str = "file", advice: str = "") -> dict | list:
    """The JSON in a file.

    Parameters
    ----------
    path : str or Path
        The file.
    what : str, default "file"
        What the file is, as a message names it.
    advice : str, default ""
        What to do about a bad file, appended to a message.

    Returns
    -------
    dict or list
        The JSON read.

    Raises
    ------
    StoreError
        The file is missing, truncated, garbage or not a regular file (the message names it and `advice`).
    """
    path = Path(path)
    check_regular(path, advice, what)
    try:
        return json.loads(path.read_text())
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as e:
        raise StoreError(
            f"{path}: this {what} cannot be read as JSON ({type(e).__name__}: {e})" + (f"; {advice}" if advice else "")
        ) from None


def _jsonable(value):
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, tuple):
        return list(value)
    raise TypeError(f"{type(value).__name__} is not JSON-able")
