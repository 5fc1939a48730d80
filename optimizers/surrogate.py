"""Surrogate optimization then a gradient polish: the preprint's calibration method.

The preprint calibrated with MATLAB's `surrogateopt` and polished the result
with a local gradient method. This is that pipeline in SciPy, over the unit
cube u = (x − lower) / (upper − lower):

1. Initial design: a Latin hypercube of `n_init` points (default
   min(max(2·dim + 1, 20), 20 % of the budget), at least dim + 2 so the
   surrogate below is determined, at most the budget), asked as one batch.
2. Surrogate rounds (as `surrogateopt`): fit a radial-basis surrogate —
   `scipy.interpolate.RBFInterpolator`, cubic kernel with a linear (degree 1)
   polynomial tail, `smoothing` 1e-10 — to every point evaluated so far
   (exact duplicates dropped; failed evaluations, +inf, given the worst
   finite value so the surrogate steers away from them; values above the
   median clipped to the median, as in Regis & Shoemaker's methods, so that a
   few huge values don't flatten the model where it matters; then
   standardized). Draw `n_candidates` (1000) candidates, half Gaussian
   perturbations of the best point with a scale `sigma` (in box widths;
   starts at 0.2, doubles after 3 successful rounds in a row up to 0.5,
   halves after max(4, dim) / batch_size failed ones, and returns to 0.2
   when it drops below 0.2/64; each coordinate is perturbed with
   probability `perturb_prob`, default 1, at least one per candidate —
   DYCORS' choice for high dimensions, not clearly better here), half
   uniform in the box. Score each by `surrogateopt`'s merit w·S + (1 − w)·D, S the surrogate value scaled to
   [0, 1] over the candidates and D = (d_max − d)/(d_max − d_min) with d
   the distance to the nearest evaluated point; the weight w cycles through
   `weights` (0.3, 0.5, 0.8, 0.95) — from exploring to exploiting — one step
   per point proposed. A round proposes the `batch_size` (4) best-merit
   candidates one after the other, each one counting as evaluated for the
   distances of the next (so the batch spreads out). A round succeeds when
   it improves the best value by more than 1e-3 of its magnitude.
3. Polish: once all but `polish_fraction` (0.3) of the budget is spent,
   L-BFGS-B (`scipy.optimize.minimize`, bounds the box) starts from the best
   point. Its gradients are forward differences with step `fd_step` (1e-3 box
   widths; backward at the upper bound), and each (value, gradient) it asks
   for is ONE batch of dim + 1 points (dim when the centre was evaluated
   already). SciPy runs in a worker thread (`optimizers.bridge`) that hands each batch to `ask` and
   waits for `tell`; it stops when L-BFGS-B converges or the next batch
   would not fit in the budget, and the thread ends then. Polishing is skipped
   when its share of the budget can't pay for one gradient.
4. Whatever the polish leaves over goes back to surrogate rounds.

Options: n_init, batch_size, n_candidates, weights, perturb_prob,
polish_fraction, fd_step, smoothing. `polish_log` records each polish:
evaluations at its start and end, the best value before and after, and how
it ended.

One caveat of the inverted control: an optimizer abandoned in the middle of
the polish (asked and never told, or dropped before its budget is spent)
leaves its worker thread waiting; the thread is a daemon and `close()` ends it.
"""

from __future__ import annotations

import functools
import math

import numpy as np

from optimizers.base import Optimizer
from optimizers.bridge import Bridge, Stop
from optimizers.registry import register


@register("surrogate")
class Surrogate(Optimizer):
    """RBF surrogate search (MATLAB surrogateopt-like) + L-BFGS-B polish with batched finite differences."""

    OPTIONS = (
        "batch_size",
        "fd_step",
        "n_candidates",
        "n_init",
        "perturb_prob",
        "polish_fraction",
        "smoothing",
        "weights",
    )

    SIGMA_INIT, SIGMA_MAX, SIGMA_MIN = 0.2, 0.5, 0.2 / 64

    def __init__(self, dim: int, budget: int, seed: int = 0, lower=-1.0, upper=1.0, **options):
        super().__init__(dim, budget, seed, lower, upper, **options)
        o, d = self.options, self.dim
        self.batch_size = int(o.get("batch_size", 4))
        self.n_candidates = int(o.get("n_candidates", 1000))
        self.weights = tuple(float(w) for w in o.get("weights", (0.3, 0.5, 0.8, 0.95)))
        self.fd_step = float(o.get("fd_step", 1e-3))
        self.smoothing = float(o.get("smoothing", 1e-10))
        self.perturb_prob = float(o.get("perturb_prob", 1.0))
        polish_fraction = float(o.get("polish_fraction", 0.3))
        if self.batch_size < 1 or self.n_candidates < 1 or not self.weights or not 0 <= polish_fraction <= 1:
            raise ValueError(f"{self.name}: bad options {o}")
        if not 0 < self.fd_step < 0.5:
            raise ValueError(f"{self.name}: fd_step must be in (0, 0.5) box widths, but got {self.fd_step}")
        default_init = max(d + 2, min(max(2 * d + 1, 20), round(0.2 * self.budget)))
        self.n_init = max(1, min(int(o.get("n_init", default_init)), self.budget))
        self.polish_budget = round(polish_fraction * self.budget)
        if self.polish_budget < d or self.budget - self.polish_budget < self.n_init:
            self.polish_budget = 0  # can't pay for one gradient, or would eat into the initial design
        self._width = self.upper - self.lower
        self._design = self._latin_hypercube(self.n_init)
        self._U: list[np.ndarray] = []  # unit-cube points evaluated, in the order told
        self._Y: list[float] = []
        self._cache: dict[bytes, float] = {}  # unit-cube point → value, for the polish's centres
        self._sigma = self.SIGMA_INIT
        self._successes = self._failures = 0
        self._fail_tol = max(1, math.ceil(max(4, d) / self.batch_size))
        self._cycle = 0
        self._asked = "init"  # what the pending batch is: "init", "search" or "polish"
        self._polished = self.polish_budget == 0
        self._bridge: Bridge | None = None  # the L-BFGS-B polish in its worker thread
        self._request: np.ndarray | None = None  # the batch (k, dim) the polish waits for
        self.polish_log: list[dict] = []

    # ask / tell

    def _ask(self, n_max: int) -> np.ndarray:
        if len(self._U) < self.n_init:
            u = self._design[len(self._U) :][:n_max]
            self._asked = "init"
            return self._to_x(u)
        if not self._polished and self.remaining <= self.polish_budget:
            self._start_polish()
        if self._request is not None:
            self._asked = "polish"
            return self._to_x(self._request)
        k = min(n_max, self.batch_size)
        if not self._polished:
            k = min(k, self.remaining - self.polish_budget)
        self._asked = "search"
        return self._to_x(self._propose(k))

    def _tell(self, x, y) -> None:
        best_before = min(self._Y, default=np.inf)
        if self._asked == "polish":
            u = self._request  # the exact points the thread asked for (x went through a round trip)
            self._request = None
        else:
            u = np.clip((x - self.lower) / self._width, 0.0, 1.0)
        for ui, yi in zip(u, y):
            self._U.append(ui)
            self._Y.append(float(yi))
            self._cache[ui.tobytes()] = float(yi)
        if self._asked == "search":
            self._adapt(best_before, float(np.min(y)))
        elif self._asked == "polish":
            self._bridge.reply(np.asarray(y, dtype=np.float64))
            self._receive()

    def close(self) -> None:
        """End the polish thread if it is waiting (only needed when abandoning a run mid-polish)."""
        if self._bridge is not None:
            self._request = None
            self._finish(self._bridge.stop())

    # surrogate rounds

    def _propose(self, k: int) -> np.ndarray:
        U, Y = np.array(self._U), np.array(self._Y)
        finite = np.isfinite(Y)
        if finite.sum() < self.dim + 2:
            return self.rng.uniform(0.0, 1.0, (k, self.dim))
        y = np.where(finite, Y, Y[finite].max())
        U, first = np.unique(U, axis=0, return_index=True)
        y = np.minimum(y[first], np.median(y[first]))
        y = (y - y.mean()) / (y.std() or 1.0)
        model = self._fit(U, y)
        best = np.array(self._U[int(np.argmin(Y))])
        n_local = self.n_candidates // 2
        step = self._sigma * self.rng.standard_normal((n_local, self.dim))
        if self.perturb_prob < 1.0:
            mask = self.rng.uniform(size=step.shape) < self.perturb_prob
            mask[np.arange(n_local), self.rng.integers(0, self.dim, n_local)] = True
            step = step * mask
        cand = np.concatenate([best + step, self.rng.uniform(0.0, 1.0, (self.n_candidates - n_local, self.dim))])
        cand = np.clip(cand, 0.0, 1.0)
        if model is None:  # the fit failed even with more smoothing: explore
            return self.rng.uniform(0.0, 1.0, (k, self.dim))
        s = model(cand)
        s = (s - s.min()) / (np.ptp(s) or 1.0)
        from scipy.spatial import cKDTree  # SciPy's modules here: `import optimizers` stays light

        dist = cKDTree(U).query(cand)[0]
        too_close = 1e-6 * math.sqrt(self.dim)
        chosen = []
        for _ in range(k):
            w = self.weights[self._cycle % len(self.weights)]
            self._cycle += 1
            ok = dist > too_close
            if not ok.any():
                chosen.append(self.rng.uniform(0.0, 1.0, self.dim))
                continue
            dmin, dmax = dist[ok].min(), dist[ok].max()
            dscore = (dmax - dist) / ((dmax - dmin) or 1.0)
            merit = np.where(ok, w * s + (1.0 - w) * dscore, np.inf)
            i = int(np.argmin(merit))
            chosen.append(cand[i])
            dist = np.minimum(dist, np.linalg.norm(cand - cand[i], axis=1))
        return np.array(chosen)

    def _fit(self, U: np.ndarray, y: np.ndarray):
        from scipy.interpolate import RBFInterpolator

        for smoothing in (self.smoothing, 1e-6, 1e-3):
            try:
                return RBFInterpolator(U, y, kernel="cubic", degree=1, smoothing=smoothing)
            except (np.linalg.LinAlgError, ValueError):
                continue
        return None

    def _adapt(self, best_before: float, batch_best: float) -> None:
        if np.isfinite(batch_best) and batch_best < best_before - 1e-3 * abs(
            best_before if np.isfinite(best_before) else 0
        ):
            self._successes, self._failures = self._successes + 1, 0
        else:
            self._successes, self._failures = 0, self._failures + 1
        if self._successes >= 3:
            self._sigma, self._successes = min(2 * self._sigma, self.SIGMA_MAX), 0
        if self._failures >= self._fail_tol:
            self._sigma, self._failures = self._sigma / 2, 0
            if self._sigma < self.SIGMA_MIN:
                self._sigma = self.SIGMA_INIT

    # polish: L-BFGS-B in a worker thread, one batch per (value, gradient)

    def _start_polish(self) -> None:
        self._polished = True
        Y = np.array(self._Y)
        i = int(np.argmin(Y))
        if not np.isfinite(Y[i]):
            return
        self.polish_log.append({"nfev_start": self.nfev, "fun_start": float(Y[i])})
        self._bridge = Bridge(
            functools.partial(self._polish, self._U[i].copy()), name=f"surrogate-polish-seed{self.seed}"
        )
        self._bridge.start()
        self._receive()

    def _receive(self) -> None:
        """Wait for the polish thread's next message: a batch to evaluate, or its end."""
        try:
            kind, payload = self._bridge.next()
        except RuntimeError as error:
            self._bridge = None
            raise RuntimeError(f"{self.name}: the L-BFGS-B polish failed") from error.__cause__
        if kind == "request":
            self._request = payload
            return
        self._finish(payload)

    def _finish(self, message) -> None:
        self._bridge = None
        self.polish_log[-1].update(nfev_end=self.nfev, fun_end=float(np.min(self._Y)), message=message)

    def _polish(self, u0: np.ndarray, request) -> str:
        # runs in the worker thread; the main thread waits in _receive meanwhile, so reading
        # self.remaining and self._cache here is safe
        d, h = self.dim, self.fd_step

        def value_and_gradient(u):
            u = np.clip(np.asarray(u, dtype=np.float64), 0.0, 1.0)
            steps = np.where(u + h <= 1.0, h, -h)
            points = u + np.diag(steps)
            f0 = self._cache.get(u.tobytes())
            if f0 is None:
                points = np.vstack([u, points])
            if len(points) > self.remaining:
                raise Stop("budget spent")
            values = request(points)
            if f0 is None:
                f0, values = values[0], values[1:]
            if not np.isfinite(f0):
                return 1e300, np.zeros(d)  # a failed centre: make the line search back off
            g = np.where(np.isfinite(values), (values - f0) / steps, 0.0)
            return float(f0), g

        from scipy.optimize import minimize as scipy_minimize

        res = scipy_minimize(
            value_and_gradient,
            u0,
            jac=True,
            method="L-BFGS-B",
            bounds=[(0.0, 1.0)] * d,
            options={"maxiter": 10**6, "maxfun": 10**6},
        )  # a Stop ("budget spent", "closed") ends the run with its message (the bridge's result)
        return f"L-BFGS-B: {res.message}"

    # helpers

    def _to_x(self, u: np.ndarray) -> np.ndarray:
        return self.lower + np.asarray(u) * self._width

    def _latin_hypercube(self, n: int) -> np.ndarray:
        strata = np.stack([self.rng.permutation(n) for _ in range(self.dim)], axis=1)
        return (strata + self.rng.uniform(0.0, 1.0, (n, self.dim))) / n
