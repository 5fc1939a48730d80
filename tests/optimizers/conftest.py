"""Fixtures for the calibrator tests: a third-party optimizer installed through the entry-point group."""

import importlib
import os
import sys
import textwrap

import pytest

THIRD_PARTY_NAME = "third-party-random"

_THIRD_PARTY_SOURCE = '''
"""A stand-in third-party calibrator: not registered by wrist-env, only declared as an entry point."""

from optimizers import Optimizer


class ThirdPartyRandom(Optimizer):
    """Uniform random points, `batch_size` (default 4) per ask."""

    OPTIONS = ("batch_size",)

    def _ask(self, n_max):
        k = min(n_max, int(self.options.get("batch_size", 4)))
        return self.rng.uniform(self.lower, self.upper, (k, self.dim))
'''


def install_third_party_package(root) -> None:
    """Write the package `thirdparty_opt` and its dist-info (entry point `third-party-random`) into `root`."""
    package = root / "thirdparty_opt"
    package.mkdir()
    (package / "__init__.py").write_text(_THIRD_PARTY_SOURCE)
    dist_info = root / "thirdparty_opt-0.1.dist-info"
    dist_info.mkdir()
    (dist_info / "METADATA").write_text("Metadata-Version: 2.1\nName: thirdparty_opt\nVersion: 0.1\n")
    (dist_info / "entry_points.txt").write_text(
        textwrap.dedent(f"""\
        [wrist_env.optimizers]
        {THIRD_PARTY_NAME} = thirdparty_opt:ThirdPartyRandom
        """)
    )


@pytest.fixture
def third_party_optimizer(tmp_path, monkeypatch):
    """Install a third-party calibrator for this test; yields its name, "third-party-random".

    The package lives in tmp_path, which is prepended to sys.path (this process)
    and to PYTHONPATH (subprocesses, e.g. `wrist-bench` run as a command), so
    `optimizers.available()` finds it through the `wrist_env.optimizers`
    entry-point group. Afterwards the name is removed from the registry and the
    module from sys.modules, so other tests see only the built-in calibrators.
    """
    from optimizers import registry

    root = tmp_path / "site"
    root.mkdir()
    install_third_party_package(root)
    monkeypatch.syspath_prepend(str(root))  # also invalidates the import caches
    monkeypatch.setenv("PYTHONPATH", os.pathsep.join(filter(None, [str(root), os.environ.get("PYTHONPATH")])))
    importlib.invalidate_caches()
    yield THIRD_PARTY_NAME
    registry._REGISTRY.pop(THIRD_PARTY_NAME, None)
    sys.modules.pop("thirdparty_opt", None)
