"""Numba's cache folder follows the kernels' sources (`wrist_env.kernel_cache`)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

from wrist_env import kernel_cache

KERNEL = """from numba import njit
from pkg.consts import N


@njit(cache=True)
def n():
    return N
"""


def _package(root: Path, configured: bool) -> Path:
    pkg = root / "pkg"
    pkg.mkdir()
    init = (  # the module alone: importing wrist_env would configure the cache for wrist_env's own kernels
        "import importlib.util\nfrom pathlib import Path\n"
        f"spec = importlib.util.spec_from_file_location('kernel_cache', {kernel_cache.__file__!r})\n"
        "module = importlib.util.module_from_spec(spec)\nspec.loader.exec_module(module)\n"
        "module.configure(Path(__file__).parent)\n"
    )
    (pkg / "__init__.py").write_text(init if configured else "")
    (pkg / "kernel.py").write_text(KERNEL)
    (pkg / "consts.py").write_text("from pkg.units import MM\nN = 1\n")
    (pkg / "units.py").write_text("MM = 1.0\n")
    (pkg / "cli.py").write_text("import argparse\n")
    return pkg


def _run(root: Path) -> int:
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    env["PYTHONPATH"] = str(root)
    out = subprocess.run(
        [sys.executable, "-c", "import pkg.kernel; print(pkg.kernel.n())"],
        env=env,
        cwd=root,
        capture_output=True,
        text=True,
        check=True,
    )
    return int(out.stdout.split()[-1])


def test_the_digest_covers_what_kernels_import_and_nothing_else(tmp_path):
    pkg = _package(tmp_path, configured=False)
    assert set(kernel_cache.kernel_sources(pkg)) == {"pkg", "pkg.kernel", "pkg.consts", "pkg.units"}
    before = kernel_cache.source_digest(pkg)
    (pkg / "cli.py").write_text("import argparse  # a comment\n")
    assert kernel_cache.source_digest(pkg) == before
    (pkg / "units.py").write_text("MM = 1e-3\n")  # two imports away from the kernel
    assert kernel_cache.source_digest(pkg) != before


def test_a_changed_constant_of_another_module_is_compiled_afresh(tmp_path):
    """Numba alone keeps the constant it compiled (its cache checks the kernel's own file); under
    `configure` the changed module names a new cache folder, so the kernel compiles with the new one."""
    for configured, expected in ((False, 1), (True, 2)):
        root = tmp_path / str(configured)
        root.mkdir()
        pkg = _package(root, configured)
        assert _run(root) == 1
        (pkg / "consts.py").write_text("from pkg.units import MM\nN = 2\n")
        assert _run(root) == expected, "Numba's cache now follows imported modules: kernel_cache may go"


def test_a_folder_set_beforehand_is_kept(tmp_path, monkeypatch):
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path / "mine"))
    assert kernel_cache.configure(_package(tmp_path, configured=False)) == str(tmp_path / "mine")


def test_old_versions_are_pruned_to_the_most_recent(tmp_path, monkeypatch):
    monkeypatch.delenv("NUMBA_CACHE_DIR", raising=False)
    pkg = _package(tmp_path, configured=False)
    root = pkg / "__pycache__" / "numba"
    for i in range(kernel_cache.KEEP_VERSIONS + 2):
        (root / f"old{i}").mkdir(parents=True)
        os.utime(root / f"old{i}", (i, i))
    folder = Path(kernel_cache.configure(pkg))
    assert folder.parent == root and folder.name == kernel_cache.source_digest(pkg)
    kept = {p.name for p in root.iterdir()} - {folder.name}
    assert kept == {f"old{i}" for i in range(2, kernel_cache.KEEP_VERSIONS + 2)}
