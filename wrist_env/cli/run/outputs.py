"""Checks of a command's output path before its work starts (not after a run of minutes or hours, losing it):
not empty, not a file where a folder goes (or the reverse), and in a folder this process can write."""

from __future__ import annotations

import os
import uuid
from pathlib import Path

from wrist_env.errors import UsageError


def out_folder(path: str | os.PathLike, option: str = "--out") -> Path:
    """`path` as a Path once it can be the folder `option` names: `UsageError` naming the option and
    the path if it is empty, a file, under a file, or under a folder this process cannot write in."""
    p = _given(path, option, "folder")
    if p.exists() and not p.is_dir():
        raise UsageError(f"{option} {path}: a file, not a folder; give a folder (new or existing)")
    _writable(p if p.is_dir() else _existing_parent(p, option, path), option, path)
    return p


def out_file(path: str | os.PathLike, option: str = "--out") -> Path:
    """`path` as a Path once it can be the file `option` names: `UsageError` naming the option and the
    path if it is empty, a folder, under a file, or a file or folder this process cannot write."""
    p = _given(path, option, "file")
    if p.is_dir():
        raise UsageError(f"{option} {path}: a folder, not a file; give the file's path (e.g. {p / 'out.json'})")
    if p.is_file():
        try:
            with open(p, "ab"):  # appends nothing: the file is left as it is
                pass
        except OSError as e:
            raise UsageError(f"{option} {path}: cannot be written ({e.strerror or e})") from None
        return p
    _writable(_existing_parent(p, option, path), option, path)
    return p


def _given(path, option: str, what: str) -> Path:
    if not str(path).strip():
        raise UsageError(f"{option} is empty; give the output {what}'s path")
    return Path(path)


def _existing_parent(p: Path, option: str, path) -> Path:
    """The nearest folder above `p` that exists; `UsageError` if a file is in the way."""
    parent = p.absolute().parent
    while not parent.exists():
        parent = parent.parent
    if not parent.is_dir():
        raise UsageError(f"{option} {path}: {parent} is a file, so nothing can be written under it")
    return parent


def _writable(folder: Path, option: str, path) -> None:
    """`UsageError` unless a file can be created in `folder` (tried: permissions alone do not tell, e.g. for
    root, on a read-only mount or under /proc)."""
    probe = folder / f".wrist-bench-probe.{uuid.uuid4().hex}.tmp"  # a name `io.clean_temporary` removes
    try:
        probe.write_bytes(b"")
        probe.unlink()
    except OSError as e:
        raise UsageError(f"{option} {path}: cannot write in {folder} ({e.strerror or e})") from None
