"""Where Numba caches the compiled kernels: one folder per version of the kernels' sources.

Numba's on-disk cache (`@njit(cache=True)`) checks a function against its own file only (modification
time and size). A kernel compiles the constants it reads from other modules into its code, so when only
such a module changes, the cache keeps the old constants: after the hamate became a free body
(`model.FREE`) while `solver/preconditioner.py` stayed as it was, the cached block mass still solved
the old bodies and every hold of P1's sweep ran to its limit (`docs/history.md`). Nothing warns of it.

So the cache folder is named by a digest of every module that defines a kernel and of every package
module those import, transitively (`kernel_sources`): a change to any of them compiles everything
afresh into a new folder; a change elsewhere (the command line, the studies) keeps the cache.
`configure` points Numba there (`NUMBA_CACHE_DIR`) when this package is imported, before any kernel is
defined; the processes it starts (the compile helper, dask's and the benchmark's workers) inherit it.
A `NUMBA_CACHE_DIR` set beforehand is left alone: that folder is its owner's to clear.
"""

from __future__ import annotations

import hashlib
import os
import re
import shutil
import sys
from pathlib import Path

__all__ = ["KEEP_VERSIONS", "configure", "kernel_sources", "source_digest"]

KEEP_VERSIONS = 3
"""Cache folders of other source versions kept beside the current one (the most recently used)."""
_IMPORT = re.compile(r"^\s*(?:from\s+([\w.]+)\s+import\s+(\([^)]*\)|[^\n]+)|import\s+([\w.]+))", re.M)
_KERNEL = re.compile(r"\bnjit\b|\bnumba\b")


def _module_name(package: Path, path: Path) -> str:
    parts = [package.name, *path.relative_to(package).with_suffix("").parts]
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def kernel_sources(package: Path) -> dict[str, str]:
    """The sources of a package's modules that mention Numba and of every package module they import.

    Parameters
    ----------
    package : Path
        The package's folder.

    Returns
    -------
    dict of str to str
        Module name → source text, for the modules that mention Numba and every module of the package they
        import, directly or through others (an import inside a function counts too).
    """
    texts = {_module_name(package, p): p.read_text(encoding="utf-8") for p in sorted(package.rglob("*.py"))}
    todo = [name for name, text in texts.items() if _KERNEL.search(text)]
    found: dict[str, str] = {}
    while todo:
        name = todo.pop()
        if name in found:
            continue
        found[name] = texts[name]
        for m in _IMPORT.finditer(texts[name]):
            base = m.group(1) or m.group(3)
            named = [n.split(" as ")[0] for n in re.split(r"[,\s()]+", m.group(2) or "") if n and n != "as"]
            for candidate in [base, *(f"{base}.{n}" for n in named)]:
                parts = candidate.split(".")
                todo += [".".join(parts[:i]) for i in range(1, len(parts) + 1) if ".".join(parts[:i]) in texts]
    return found


def source_digest(package: Path) -> str:
    """16 hex digits of SHA-256 over `kernel_sources(package)` (names and texts, in name order).

    Parameters
    ----------
    package : Path
        The package's folder (`wrist_env/`), whose kernels' sources are hashed.

    Returns
    -------
    str
        The digest, 16 hex digits: the name of the kernels' cache folder.
    """
    h = hashlib.sha256()
    for name, text in sorted(kernel_sources(package).items()):
        h.update(name.encode())
        h.update(b"\0")
        h.update(text.encode())
        h.update(b"\0")
    return h.hexdigest()[:16]


def _root(package: Path) -> Path:
    """Beside the package's own bytecode if it may write there (a checkout, a user's install), else in the
    user's cache (`WRIST_ENV_CACHE`, `~/.cache/wrist_env`)."""
    here = package / "__pycache__"
    try:
        here.mkdir(exist_ok=True)
        if os.access(here, os.W_OK):
            return here / "numba"
    except OSError:
        pass
    return Path(os.environ.get("WRIST_ENV_CACHE", Path.home() / ".cache" / "wrist_env")) / "numba"


def _prune(root: Path, current: Path) -> None:
    """Remove the cache folders of other source versions but the `KEEP_VERSIONS` most recently used."""
    others = sorted(
        (p for p in root.iterdir() if p.is_dir() and p != current), key=lambda p: p.stat().st_mtime, reverse=True
    )
    for old in others[KEEP_VERSIONS:]:
        shutil.rmtree(old, ignore_errors=True)


def configure(package: Path | None = None) -> str:
    """Point Numba's cache at the folder of a package's kernel sources, unless `NUMBA_CACHE_DIR` is set already.

    Parameters
    ----------
    package : Path, optional
        The package's folder (this package by default).

    Returns
    -------
    str
        The folder Numba caches in.
    """
    if os.environ.get("NUMBA_CACHE_DIR"):
        return os.environ["NUMBA_CACHE_DIR"]
    package = Path(__file__).resolve().parent if package is None else Path(package)
    root = _root(package)
    folder = root / source_digest(package)
    if not folder.is_dir():
        folder.mkdir(parents=True, exist_ok=True)
        _prune(root, folder)
    os.utime(folder)
    os.environ["NUMBA_CACHE_DIR"] = str(folder)
    if "numba" in sys.modules:  # imported before this package: its configuration read the environment already
        sys.modules["numba"].config.CACHE_DIR = str(folder)
    return str(folder)
