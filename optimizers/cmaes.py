"""CMA-ES: `cma.CMAEvolutionStrategy` behind ask/tell, one population per batch, restarted until the budget.

`cma` samples from NumPy's global random state (seeded by its `seed` option).
So that two CMA-ES runs (or anything else using `np.random`) can interleave
without disturbing each other, every call into `cma` runs with this
optimizer's own copy of that global state swapped in; the result is
bit-for-bit the same as running `cma` alone with the same seed.
"""

from __future__ import annotations

import contextlib

import numpy as np

from optimizers.base import Optimizer
from optimizers.registry import register


@register("cmaes")
class CMAES(Optimizer):
    """CMA-ES (Hansen's `cma`), bounded by its BoundTransform, with restarts.

    Options:
      x0: start mean of the first run (default: where the seed puts it, a draw from the prior,
        `base.prior_draw`: Table 2's normals truncated at ±3 SD as `table2.sample_materials` draws
        them, from the seeded `self.rng`);
      sigma0: initial step size as a fraction of the box width (default 0.3);
        with unequal widths it is passed as sigma0 = fraction and
        CMA_stds = widths;
      popsize: default CMA's 4 + floor(3 ln dim);
      restart: "ipop" (default: double the population at each restart) or
        "plain" (same population); restarts start from a uniform random
        point in the box and get a fresh cma seed from `self.rng`;
      cma_options: further options for `cma` (e.g. {"tolfun": 1e-12}).
    The first run is CMAEvolutionStrategy(x0, sigma0, {"bounds": [lower, upper],
    "seed": seed + 1, "verbose": -9, "maxfevals": budget, ...}) — seed + 1
    because cma treats seed 0 as "seed from the clock". A population is one
    batch; when fewer points than a population remain, the batch is truncated,
    those points are evaluated and recorded, but cma is not told about them.
    A run that stops before the budget (es.stop()) is restarted.
    """

    OPTIONS = ("cma_options", "popsize", "restart", "sigma0", "x0")

    def __init__(self, dim: int, budget: int, seed: int = 0, lower=-1.0, upper=1.0, **options):
        super().__init__(dim, budget, seed, lower, upper, **options)
        self.x0 = self.start_point()
        self.restart = self.choice("restart", ("ipop", "plain"))
        self.popsize = int(options.get("popsize", 4 + int(3 * np.log(self.dim))))
        self.restarts = 0
        self._np_state = None
        self._population = None
        self.es = self._new_es(self.x0, self.popsize, (self.seed % (2**32 - 1)) + 1)

    @contextlib.contextmanager
    def _own_np_random(self):
        """Run the body with this optimizer's NumPy global random state swapped in."""
        outer = np.random.get_state()
        if self._np_state is not None:
            np.random.set_state(self._np_state)
        try:
            yield
        finally:
            self._np_state = np.random.get_state()
            np.random.set_state(outer)

    def cma_options(self, popsize: int, seed: int, maxfevals: int) -> dict:
        """The options handed to `cma.CMAEvolutionStrategy` for one run."""
        width = self.upper - self.lower
        opts = {
            "bounds": [self.lower.tolist(), self.upper.tolist()],
            "seed": seed,
            "popsize": popsize,
            "verbose": -9,
            "maxfevals": maxfevals,
        }
        if not np.all(width == width[0]):
            opts["CMA_stds"] = width.tolist()
        opts.update(self.options.get("cma_options", {}))
        return opts

    def sigma0(self) -> float:
        width = self.upper - self.lower
        fraction = float(self.options.get("sigma0", 0.3))
        return fraction * float(width[0]) if np.all(width == width[0]) else fraction

    def _new_es(self, x0, popsize: int, seed: int):
        import cma

        self._np_state = None  # cma seeds the global state itself
        with self._own_np_random():
            return cma.CMAEvolutionStrategy(
                np.asarray(x0, dtype=np.float64).tolist(),
                self.sigma0(),
                self.cma_options(popsize, seed, self.remaining),
            )

    def _ask(self, n_max: int) -> np.ndarray:
        with self._own_np_random():
            stopped = bool(self.es.stop())
        if stopped:
            self.restarts += 1
            if self.restart == "ipop":
                self.popsize *= 2
            self.es = self._new_es(
                self.rng.uniform(self.lower, self.upper), self.popsize, int(self.rng.integers(1, 2**31))
            )
        with self._own_np_random():
            self._population = self.es.ask()
        return np.array(self._population[:n_max])

    def _tell(self, x, y) -> None:
        if len(y) == len(self._population):
            with self._own_np_random():
                self.es.tell(self._population, y.tolist())
        self._population = None
