"""Nelder–Mead: SciPy's bounded simplex method behind ask/tell, restarted until the budget is spent.

SciPy drives the objective itself (callback style), so control is inverted
(`optimizers.bridge`): SciPy runs in a daemon worker thread whose objective
hands each point to `ask` and blocks until `tell` sends the value back. Only
one side runs at a time, so the run is deterministic. When the budget is
spent (or the optimizer is closed or garbage-collected) the objective raises
`bridge.Stop` inside SciPy, which unwinds the worker thread.
"""

from __future__ import annotations

import functools

import numpy as np
from numpy.typing import ArrayLike

from optimizers.base import Optimizer
from optimizers.bridge import Bridge, Stop
from optimizers.registry import register


def initial_simplex(x0: ArrayLike, lower: np.ndarray, upper: np.ndarray, scale: float = 0.25) -> np.ndarray:
    """(dim + 1, dim): x0 and x0 ± scale·(upper − lower) along each axis.

    Each step goes up unless that leaves the box, then down (SciPy would
    otherwise clip or reflect the vertex).
    """
    x0 = np.asarray(x0, dtype=np.float64)
    step = scale * (upper - lower)
    step = np.where(x0 + step <= upper, step, -step)
    sim = np.tile(x0, (len(x0) + 1, 1))
    sim[1:] += np.diag(step)
    return sim


def _runs(request, budget, lower, upper, x0, rng, scale, restart, perturb, options) -> None:
    """SciPy's Nelder–Mead with restarts until `budget` evaluations; `request(x)` evaluates one point."""
    evals = 0
    best_x, best_f = None, np.inf

    def fun(x):
        nonlocal evals, best_x, best_f
        if evals >= budget:
            raise Stop("budget spent")
        x = np.array(x, dtype=np.float64)
        y = request(x)
        evals += 1
        if y < best_f:
            best_x, best_f = x, y
        return y

    from scipy.optimize import Bounds  # here: 0.35 s to import
    from scipy.optimize import minimize as scipy_minimize

    bounds = Bounds(lower, upper)
    start = x0
    while evals < budget:
        # inf values (failed evaluations) make SciPy compute inf - inf; np.errstate is
        # thread-local (unlike warnings.catch_warnings, which must not be used here)
        with np.errstate(invalid="ignore", over="ignore"):
            scipy_minimize(
                fun,
                start,
                method="Nelder-Mead",
                bounds=bounds,
                options={
                    **options,
                    "maxfev": budget - evals,
                    "initial_simplex": initial_simplex(start, lower, upper, scale),
                },
            )
        if evals >= budget:
            break
        # converged before the budget: restart
        if restart == "best" and best_x is not None:
            start = np.clip(best_x + rng.normal(0.0, perturb, len(lower)) * (upper - lower), lower, upper)
        else:
            start = rng.uniform(lower, upper)


@register("nelder-mead")
class NelderMead(Optimizer):
    """`scipy.optimize.minimize(method="Nelder-Mead", bounds=...)`, one point per ask, restarted until the budget.

    The first run starts where the seed puts it: at a draw from the prior (`base.prior_draw`: Table 2's
    normals truncated at ±3 SD, as `table2.sample_materials` draws them) from the seeded `self.rng`,
    so each seed is another run (before issue 55 every seed started at the box centre, the population
    design, and gave the same run).

    Options:
      x0: start of the first run (default the seed's draw from the prior; the box centre is x0=0 on
        the benchmark's box);
      simplex_scale: initial simplex x0 + simplex_scale·(upper − lower)·e_i
        (default 0.25; steps go down where up would leave the box);
      restart: where a run starts after SciPy converges before the budget —
        "random" (uniform in the box, default) or "best" (the best point so
        far plus N(0, perturb·(upper − lower)), clipped);
      perturb: default 0.1;
      xatol, fatol, adaptive: SciPy's (defaults 1e-4, 1e-4, False).
    Each run gets maxfev = the remaining budget. Given its start, the first run is deterministic;
    the start (without x0) and the restarts draw from `self.rng`.
    """

    OPTIONS = ("adaptive", "fatol", "perturb", "restart", "simplex_scale", "x0", "xatol")

    def __init__(self, dim: int, budget: int, seed: int = 0, lower=-1.0, upper=1.0, **options):
        super().__init__(dim, budget, seed, lower, upper, **options)
        self.x0 = self.start_point()
        self.restart = self.choice("restart", ("random", "best"))
        self._scipy_options = {
            "xatol": float(options.get("xatol", 1e-4)),
            "fatol": float(options.get("fatol", 1e-4)),
            "adaptive": bool(options.get("adaptive", False)),
        }
        self._bridge: Bridge | None = None

    def _ask(self, n_max: int) -> np.ndarray:
        if self._bridge is None:
            run = functools.partial(
                _runs,
                budget=self.budget,
                lower=self.lower,
                upper=self.upper,
                x0=self.x0,
                rng=self.rng,
                scale=float(self.options.get("simplex_scale", 0.25)),
                restart=self.restart,
                perturb=float(self.options.get("perturb", 0.1)),
                options=self._scipy_options,
            )
            self._bridge = Bridge(run, name=f"nelder-mead-{id(self):x}")
            self._bridge.start()
        elif self._bridge.finished:
            raise RuntimeError(f"{self.name}: the optimizer was closed")
        kind, x = self._bridge.next()
        if kind == "done":  # cannot happen while budget remains; kept as a guard
            raise RuntimeError(f"{self.name}: the worker ended with {self.remaining} evaluations left")
        return x[None, :]

    def _tell(self, x, y) -> None:
        self._bridge.reply(float(y[0]))
        if self.remaining <= 0:
            self.close()

    def close(self) -> None:
        """End the worker thread (done automatically when the budget is spent)."""
        if self._bridge is not None:
            self._bridge.stop()

    def __del__(self):
        # the worker holds no reference to self; unblock it so the thread ends
        try:
            if getattr(self, "_bridge", None) is not None:
                self._bridge.abandon()
        except Exception:  # noqa: BLE001  (interpreter shutdown)
            pass
