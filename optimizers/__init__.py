"""Calibrators for wrist-env: ask/tell over batches, registered by name.

`optimizers.available()` lists them; `optimizers.make(name, dim, budget, seed)`
builds one; `optimizers.minimize(opt, fun_batch)` runs it. Built in: one
module each (imported here so they register).
"""

from optimizers import (  # noqa: F401  (register; "optuna-gp" only with torch, "ng-*" only with nevergrad)
    cmaes,
    latin_hypercube,
    nelder_mead,
    nevergrad_optimizers,
    optuna_samplers,
    random_search,
    surrogate,
)
from optimizers.base import Optimizer, OptimizeResult, OptionError, minimize
from optimizers.registry import ENTRY_POINT_GROUP, UnknownOptimizerError, available, get, make, register

__all__ = [
    "ENTRY_POINT_GROUP",
    "OptimizeResult",
    "OptionError",
    "Optimizer",
    "UnknownOptimizerError",
    "available",
    "get",
    "make",
    "minimize",
    "register",
]
