"""
A custom calibrator
===================

A calibrator is an ask/tell class: a subclass of ``optimizers.Optimizer``
that proposes a batch of points (``_ask``) and learns from their values
(``_tell``), registered by name. Here a (1, λ) evolution strategy in about
twenty lines, run on P1 and compared with random search on the same budget
and seed. The Extending page says where such a file goes and which tests
hold it to the calibrators' contract.
"""

# %%
# The class: each batch is ``batch_size`` Gaussian steps around the best
# point so far, whose step size shrinks when a batch finds nothing better.
# Randomness comes from ``self.rng`` (seeded), the start from
# ``self.start_point()`` (the seed's draw from the population prior).
import matplotlib.pyplot as plt
import numpy as np

import optimizers
from optimizers import Optimizer, register


@register("gallery-es")
class GalleryES(Optimizer):
    """A (1, λ) evolution strategy: λ = batch_size steps of size sigma."""

    OPTIONS = ("batch_size", "sigma")

    def __init__(self, dim, budget, seed=0, lower=-1.0, upper=1.0, **options):
        super().__init__(dim, budget, seed, lower, upper, **options)
        self.best_x, self.best_y = self.start_point(), np.inf
        self.sigma = float(self.options.get("sigma", 0.3))

    def _ask(self, n_max):
        k = min(n_max, int(self.options.get("batch_size", 8)))
        return self.best_x + self.sigma * self.rng.standard_normal((k, self.dim))

    def _tell(self, x, y):
        i = int(np.argmin(y))
        if y[i] < self.best_y:
            self.best_x, self.best_y = x[i], y[i]
        else:
            self.sigma *= 0.5


print("registered:", "gallery-es" in optimizers.available())

# %%
# Registered, it is a calibrator like the built-in ones: ``calibrate`` (and
# ``wrist-bench benchmark``, and the contract tests) find it by name.
from wrist_env.bench import calibrate

runs = {
    name: calibrate("P1", name, budget=24, seed=0) for name in ["gallery-es", "random"]
}
for name, run in runs.items():
    print(f"{name}: best cost {run.cost:.3f} after {run.result.nfev} evaluations")

# %%
# Best so far, evaluation by evaluation, on the calibration trial.
plt.figure(figsize=(6, 3.5))
for name, run in runs.items():
    best = np.minimum.accumulate(run.result.history_fun)
    plt.step(np.arange(1, len(best) + 1), best, where="post", label=name)
plt.xlabel("evaluation")
plt.ylabel("best kinematic cost so far")
plt.title("P1, one seed: a custom calibrator against random search")
plt.legend()
plt.tight_layout()
