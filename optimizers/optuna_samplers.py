"""Optuna's samplers as calibrators: TPE, CMA-ES and the Gaussian-process sampler.

Each drives one Optuna study through its ask/tell API. The box is the search
space — one `FloatDistribution(lower_i, upper_i)` per dimension, named
x0 … x{dim-1} — and the study minimizes. A batch is `batch_size` trials asked
before any of them is told; Optuna keeps them RUNNING meanwhile, and the
samplers account for such pending trials (TPE and the GP sampler by a constant
liar, CMA-ES by its generations).

Options (all calibrators):

- batch_size: trials per ask. Defaults: 8 for "optuna-tpe"; the CMA-ES
  population size for "optuna-cmaes" (one generation per batch, so no trial
  is wasted — Optuna's CMA-ES tells the first `popsize` trials of a generation
  and ignores the rest); 1 for "optuna-gp".
- n_startup_trials: random trials before the model takes over. Defaults:
  Optuna's for TPE (10) and the GP sampler (10); 0 for CMA-ES (it starts
  where the seed puts it, sigma0 = 1/6 of the narrowest side, Optuna's default).
- storage: an Optuna storage, its URL (e.g. "sqlite:///runs/studies.db"),
  or a path without "://" — a journal file (Optuna's JournalStorage), several
  times faster than SQLite (measured, 300 trials in 22-D: ~30 s of SQLite
  overhead per run against ~4 s); in memory when not given. study_name: the
  study's name in that storage; an existing study of that name resumes
  (load_if_exists) — its earlier trials inform the sampler, while `budget`
  counts only this optimizer's own.

Sampler options: "optuna-tpe" multivariate (default True, as Optuna ≥ 4
for one objective), n_ei_candidates (24); "optuna-cmaes" popsize (default
4 + ⌊3 ln dim⌋), sigma0, use_separable_cma, restart_strategy, x0 (the start mean;
default a draw from the prior, `base.prior_draw`: Table 2's normals truncated at ±3 SD as
`table2.sample_materials` draws them, from the seeded `self.rng` — Optuna's default, the box
centre, would start every seed at the population design); "optuna-gp"
deterministic_objective (default False).

"optuna-gp" needs PyTorch, which wrist-env does not depend on (the CPU build
is a large install); it is registered only when `torch` can be imported, and
is absent from `optimizers.available()` otherwise. "optuna-cmaes" needs the
`cmaes` package (a dependency of wrist-env).
"""

from __future__ import annotations

import importlib.util
import math
import warnings
from typing import TYPE_CHECKING

import numpy as np

from optimizers.base import Optimizer
from optimizers.optuna_storage import open_storage
from optimizers.registry import register, unavailable

if TYPE_CHECKING:
    import optuna


class OptunaOptimizer(Optimizer):
    """An Optuna sampler behind the ask/tell interface (subclasses choose the sampler)."""

    default_batch_size = 1
    accepts_storage = True
    OPTIONS = ("batch_size", "n_startup_trials", "storage", "study_name")

    def __init__(self, dim: int, budget: int, seed: int = 0, lower=-1.0, upper=1.0, **options):
        import optuna

        super().__init__(dim, budget, seed, lower, upper, **options)
        optuna.logging.set_verbosity(optuna.logging.WARNING)
        self._names = [f"x{i}" for i in range(self.dim)]
        self._distributions = {
            n: optuna.distributions.FloatDistribution(float(lo), float(hi))
            for n, lo, hi in zip(self._names, self.lower, self.upper)
        }
        self.batch_size = int(self.options.get("batch_size", self._default_batch_size()))
        if self.batch_size < 1:
            raise ValueError(f"{self.name}: batch_size must be ≥ 1, but got {self.batch_size}")
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", optuna.exceptions.ExperimentalWarning)
            sampler = self._make_sampler()
        self.study = optuna.create_study(
            direction="minimize",
            sampler=sampler,
            storage=open_storage(self.options.get("storage")),
            study_name=self.options.get("study_name"),
            load_if_exists=True,
        )
        self._trials: list[optuna.trial.Trial] = []

    def _default_batch_size(self) -> int:
        return self.default_batch_size

    def _make_sampler(self) -> optuna.samplers.BaseSampler:
        raise NotImplementedError

    def _ask(self, n_max: int) -> np.ndarray:
        import optuna

        k = min(n_max, self.batch_size)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", optuna.exceptions.ExperimentalWarning)
            self._trials = [self.study.ask(self._distributions) for _ in range(k)]
        params = [t.params for t in self._trials]  # (each access copies the dict)
        return np.array([[p[n] for n in self._names] for p in params])

    def _tell(self, x, y) -> None:
        # y is finite or +inf (the base maps NaN to inf); Optuna takes inf as a value
        for trial, value in zip(self._trials, y):
            self.study.tell(trial, float(value))
        self._trials = []


@register("optuna-tpe")
class OptunaTPE(OptunaOptimizer):
    """Optuna's tree-structured Parzen estimator, with a constant liar for pending trials."""

    default_batch_size = 8
    OPTIONS = OptunaOptimizer.OPTIONS + ("multivariate", "n_ei_candidates")

    def _make_sampler(self):
        import optuna

        o = self.options
        return optuna.samplers.TPESampler(
            seed=self.seed,
            constant_liar=True,
            n_startup_trials=int(o.get("n_startup_trials", 10)),
            n_ei_candidates=int(o.get("n_ei_candidates", 24)),
            multivariate=bool(o.get("multivariate", True)),
        )


@register("optuna-cmaes")
class OptunaCMAES(OptunaOptimizer):
    """Optuna's CMA-ES sampler (the `cmaes` package); one generation per batch by default."""

    OPTIONS = OptunaOptimizer.OPTIONS + ("popsize", "restart_strategy", "sigma0", "use_separable_cma", "x0")

    @property
    def popsize(self) -> int:
        return int(self.options.get("popsize", 4 + math.floor(3 * math.log(self.dim))))

    def _default_batch_size(self) -> int:
        return self.popsize

    def _make_sampler(self):
        o = self.options
        x0 = dict(zip(self._names, self.start_point().tolist()))
        # one-dimensional spaces: Optuna's CMA-ES falls back to its independent (random) sampler
        with warnings.catch_warnings():  # Optuna ≥ 4.9 deprecates x0 (its removal is planned for 6.0)
            warnings.filterwarnings("ignore", message=".*`x0`", category=FutureWarning)
            return self._cma_sampler(x0, o)

    def _cma_sampler(self, x0: dict, o: dict):
        import optuna

        return optuna.samplers.CmaEsSampler(
            x0=x0,
            seed=self.seed,
            popsize=self.popsize,
            n_startup_trials=int(o.get("n_startup_trials", 0)),
            sigma0=o.get("sigma0"),
            restart_strategy=o.get("restart_strategy"),
            use_separable_cma=bool(o.get("use_separable_cma", False)),
            warn_independent_sampling=False,
        )


class OptunaGP(OptunaOptimizer):
    """Optuna's Gaussian-process sampler (log-EI, needs PyTorch); one trial per batch by default."""

    default_batch_size = 1
    OPTIONS = OptunaOptimizer.OPTIONS + ("deterministic_objective",)

    def _make_sampler(self):
        import optuna

        o = self.options
        return optuna.samplers.GPSampler(
            seed=self.seed,
            n_startup_trials=int(o.get("n_startup_trials", 10)),
            deterministic_objective=bool(o.get("deterministic_objective", False)),
        )


HAS_TORCH = importlib.util.find_spec("torch") is not None
if HAS_TORCH:
    register("optuna-gp")(OptunaGP)
else:
    unavailable("optuna-gp", 'it needs PyTorch; install the extra: pip install -e ".[gp]"')
