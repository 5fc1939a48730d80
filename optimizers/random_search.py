"""Random search: independent uniform points in the box (the baseline)."""

from __future__ import annotations

import numpy as np

from optimizers.base import Optimizer
from optimizers.registry import register


@register("random")
class RandomSearch(Optimizer):
    """Uniform samples in the bounds, `batch_size` per ask (default 16)."""

    OPTIONS = ("batch_size",)

    def _ask(self, n_max: int) -> np.ndarray:
        k = min(n_max, int(self.options.get("batch_size", 16)))
        return self.rng.uniform(self.lower, self.upper, (k, self.dim))
