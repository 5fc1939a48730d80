"""The cache of built models (and instances): its folder, the lock under which one is made, and the checks
of what is read from it and where it is written."""

from __future__ import annotations

import fcntl
import os
import warnings
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from wrist_env.errors import StoreError
from wrist_env.model import Model

__all__ = ["cache_dir", "cache_lock", "cached", "check_cache"]


def cache_dir() -> Path:
    """Where built models are cached.

    Returns
    -------
    Path
        `$WRIST_ENV_CACHE`, default `~/.cache/wrist_env`.
    """
    return Path(os.environ.get("WRIST_ENV_CACHE", Path.home() / ".cache" / "wrist_env"))


def cached(path: Path, name: str, digest: str, *, quiet: bool = False) -> Model | None:
    """The model cached at `path` if it is there whole and is `name`'s of source hash `digest`.

    Parameters
    ----------
    path : Path
        The cached model's path without its suffixes.
    name : str
        The participant the model must be built for.
    digest : str
        The source hash the model must have (`builder.digest.source_hash`).
    quiet : bool, default False
        Do not warn about a damaged or mismatched file.

    Returns
    -------
    Model or None
        The model; None if it is not there, or is damaged or another's (warned about, naming the file,
        unless `quiet`).
    """
    if not path.with_suffix(".json").exists():
        return None
    try:
        model = Model.load(path)
        if model.name != name or model.source_hash != digest:
            raise StoreError(
                f"{path.with_suffix('.json')} holds {model.name!r} {model.source_hash}, not {name!r} {digest}"
            )
        return model
    except StoreError as e:
        if not quiet:
            warnings.warn(f"rebuilding a damaged cached model: {e}", stacklevel=2)
        return None


@contextmanager
def cache_lock(path: Path) -> Iterator[None]:
    """Hold an flock on `.<name>.lock` beside a cached model (or instance) while making it.

    Processes that need the same uncached one at once (a study's workers, a test session's) make it once;
    the others wait and load it. The lock is released when the process dies, even by SIGKILL.

    Parameters
    ----------
    path : Path
        The cached model's path without its suffix, or the instance's folder.

    Yields
    ------
    None
        While the lock is held.
    """
    lock = path.parent / f".{path.name}.lock"
    with open(lock, "a+") as handle:
        fcntl.flock(handle, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(handle, fcntl.LOCK_UN)


def check_cache(path: Path) -> None:
    """Check, before a build of minutes, that a model can be cached at `path` (`.npz` + `.json`).

    Parameters
    ----------
    path : Path
        The cached model's path without its suffixes.

    Raises
    ------
    StoreError
        A folder stands where a file goes, or the folder cannot be written (the message names it).
    """
    advice = "set WRIST_ENV_CACHE to a writable folder, or load with cache=False"
    for p in (path.with_suffix(".npz"), path.with_suffix(".json")):
        if p.is_dir():
            raise StoreError(f"{p}: a folder where the cached model goes; remove it, or {advice}")
    probe = path.parent / f".{path.name}.probe.tmp"  # a temporary name `io.clean_temporary` knows
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        probe.write_bytes(b"")
        probe.unlink()
    except OSError as e:
        raise StoreError(f"{path.parent}: the model cache cannot be written ({e.strerror or e}); {advice}") from None
