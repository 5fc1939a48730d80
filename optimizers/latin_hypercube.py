"""Latin hypercube sampling: the whole budget as one space-filling design (a baseline)."""

from __future__ import annotations

import numpy as np

from optimizers.base import Optimizer
from optimizers.registry import register


@register("lhs")
class LatinHypercube(Optimizer):
    """One Latin hypercube design of `budget` points in the bounds, asked `batch_size` at a time.

    Options: batch_size (default 16), scramble (default True: random points
    inside the cells; False: cell centres), optimization (SciPy's None,
    "random-cd" or "lloyd"; default None). The design is drawn from `self.rng`
    on the first ask, so it depends only on the seed and the budget.
    """

    OPTIONS = ("batch_size", "optimization", "scramble")

    def _ask(self, n_max: int) -> np.ndarray:
        if not hasattr(self, "_design"):
            from scipy.stats import qmc  # scipy.stats takes 0.5 s to import: only when a design is drawn

            sampler = qmc.LatinHypercube(
                self.dim,
                scramble=bool(self.options.get("scramble", True)),
                optimization=self.options.get("optimization"),
                rng=self.rng,
            )
            self._design = qmc.scale(sampler.random(self.budget), self.lower, self.upper)
        k = min(n_max, int(self.options.get("batch_size", 16)))
        return self._design[self.nfev : self.nfev + k]
