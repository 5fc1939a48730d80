"""Calibrators for wrist-env: ask/tell over batches, registered by name.

`optimizers.available()` lists them; `optimizers.make(name, dim, budget, seed)`
builds one; `optimizers.minimize(opt, fun_batch)` runs it. Built in: one
module each (imported here so they register).
"""

from optimizers.base import OptimizeResult, OptionError, Optimizer, minimize
from optimizers.registry import ENTRY_POINT_GROUP, UnknownOptimizerError, available, get, make, register
from optimizers import random_search  # noqa: F401  (registers)
from optimizers import cmaes, latin_hypercube, nelder_mead  # noqa: F401  (register)
from optimizers import optuna_samplers, surrogate  # noqa: F401  (register; "optuna-gp" only with torch)

__all__ = ["ENTRY_POINT_GROUP", "OptimizeResult", "OptionError", "Optimizer", "UnknownOptimizerError", "available", "get",
           "make", "minimize", "register"]
