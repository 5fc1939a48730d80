"""Nevergrad's optimizers as calibrators (the optional `[nevergrad]` extra): one adapter, four methods.

    "ng-ngopt"        NGOpt, Nevergrad's algorithm selector (picks a method for the dimension,
                      budget and batch size)
    "ng-twopointsde"  TwoPointsDE, differential evolution with two-point crossover
    "ng-pso"          PSO, particle swarm (used to calibrate knee models)
    "ng-tbpsa"        TBPSA, test-based population-size adaptation (robust to noisy values)

Each drives one Nevergrad optimizer through its ask/tell API on a bounded
`nevergrad.p.Array` whose random state is seeded with the calibrator's seed, so a
run is deterministic for a seed (the benchmark resumes a cut-short cell by replay).
Its init is `x0`, by default where the seed puts it: a draw from the prior
(`base.prior_draw`: Table 2's normals truncated at ±3 SD, as `table2.sample_materials`
draws them) from the seeded `self.rng` — so NGOpt, which runs a deterministic method
(COBYLA) one point at a time for small budgets, gives another run for each seed. A batch is `batch_size`
candidates asked before any is told (`num_workers` of the optimizer; default
1, Nevergrad's default). A failed evaluation's +inf is told as it is.

Options: batch_size, x0. Registered only when `nevergrad` can be imported
(`pip install -e ".[nevergrad]"`); otherwise the names say which extra to install.
"""

from __future__ import annotations

import contextlib
import importlib.util
import warnings

import numpy as np

from optimizers.base import Optimizer
from optimizers.registry import register, unavailable

METHODS = {"ng-ngopt": "NGOpt", "ng-twopointsde": "TwoPointsDE", "ng-pso": "PSO", "ng-tbpsa": "TBPSA"}
"""Calibrator name → Nevergrad optimizer (`nevergrad.optimizers.registry` key)."""


# NGOpt's COBYLA runs in Nevergrad's background thread, outside `_quiet`; its notices about
# the settings Nevergrad passes (MAXFUN, RHOEND) are not the user's to act on
warnings.filterwarnings("ignore", message=r"COBYLA: Invalid (MAXFUN|RHOEND)", category=UserWarning)


@contextlib.contextmanager
def _quiet():
    """Nevergrad's and its solvers' warnings (inefficient settings, infinite losses, COBYLA's RHOEND) off."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        yield


class NevergradOptimizer(Optimizer):
    """A Nevergrad optimizer behind the ask/tell interface (`method` names it in Nevergrad's registry)."""

    method = ""
    OPTIONS = ("batch_size", "x0")

    def __init__(self, dim: int, budget: int, seed: int = 0, lower=-1.0, upper=1.0, **options):
        import nevergrad as ng

        super().__init__(dim, budget, seed, lower, upper, **options)
        self.batch_size = int(self.options.get("batch_size", 1))
        if self.batch_size < 1:
            raise ValueError(f"{self.name}: batch_size must be ≥ 1, but got {self.batch_size}")
        parametrization = ng.p.Array(init=self.start_point(), lower=self.lower, upper=self.upper)
        parametrization.random_state = np.random.RandomState(self.seed % (2**32))
        with _quiet():
            self.ng = ng.optimizers.registry[self.method](
                parametrization=parametrization, budget=self.budget, num_workers=self.batch_size
            )
        self._candidates: list = []

    def _ask(self, n_max: int) -> np.ndarray:
        with _quiet():
            self._candidates = [self.ng.ask() for _ in range(min(n_max, self.batch_size))]
        return np.array([c.value for c in self._candidates])

    def _tell(self, x: np.ndarray, y: np.ndarray) -> None:
        with _quiet():
            for candidate, value in zip(self._candidates, y):
                self.ng.tell(candidate, float(value))
        self._candidates = []

    def close(self) -> None:
        """Stop the background thread of a recast method (NGOpt may choose COBYLA or SciPy's, run in one)."""
        optimizer = self.ng
        for _ in range(8):  # NGOpt → the optimizer it chose → ...
            thread = getattr(optimizer, "_messaging_thread", None)
            if thread is not None:
                thread.stop()
            optimizer = getattr(optimizer, "optim", None)
            if optimizer is None:
                break


def _register_all() -> None:
    if importlib.util.find_spec("nevergrad") is None:
        for name, method in METHODS.items():
            unavailable(name, f'Nevergrad\'s {method} needs the nevergrad extra: pip install -e ".[nevergrad]"')
        return
    for name, method in METHODS.items():
        cls = type(method, (NevergradOptimizer,), {"method": method, "__doc__": f"Nevergrad's {method}."})
        register(name)(cls)


_register_all()
