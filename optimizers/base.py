"""The calibrator interface: ask/tell over batches, one result type.

A calibrator minimizes f: [lower, upper]^dim → R within a budget of
evaluations. `ask()` proposes a batch (k, dim) — a whole CMA-ES population is
one batch, so one vector-env call — never more points than the budget has
left; `tell(x, y)` returns their values. `minimize` drives the loop.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike

from wrist_env.design import SPAN_SD
from wrist_env.errors import InputError
from wrist_env.table2 import material_prior

__all__ = [
    "OptionError",
    "OptimizeResult",
    "Optimizer",
    "prior_draw",
    "minimize",
]


class OptionError(InputError):
    """An option a calibrator does not have (the message lists the ones it has).

    Raised by an `Optimizer`'s constructor (so by `make` and the benchmark) for an option name not in the
    calibrator's ``OPTIONS``; an `InputError`, so also a `ValueError`.
    """


@dataclass(frozen=True)
class OptimizeResult:
    """What every calibrator returns: SciPy's `OptimizeResult` field names plus the history.

    Parameters
    ----------
    x : ndarray of shape (dim,)
        The best point told.
    fun : float
        Its value (the kinematic cost, in the benchmark).
    nfev : int
        Evaluations used.
    success : bool
        Whether the best value is finite.
    message : str
        Why the run ended: the budget spent, or the method converged before it.
    history_x : ndarray of shape (nfev, dim)
        Every point, in the order told.
    history_fun : ndarray of shape (nfev,)
        Their values (a non-finite value is told as inf).
    """

    x: np.ndarray
    fun: float
    nfev: int
    success: bool
    message: str
    history_x: np.ndarray = field(repr=False)
    history_fun: np.ndarray = field(repr=False)


class Optimizer(ABC):
    """The calibrator interface: ask/tell over batches, within bounds and a budget of evaluations.

    The base keeps the bounds, the budget, the seed and the record of what was told; a calibrator is a
    subclass that proposes points. Asking for a batch lets a population method (CMA-ES) be one batched
    simulation per generation.

    Subclasses implement ``_ask(n_max)``, a batch of shape (k, dim) with 1 ≤ k ≤ n_max, and, if they learn
    from values, ``_tell(x, y)``. They draw randomness from ``self.rng`` (a numpy Generator seeded with
    `seed`, so a run is replayed exactly), read the bounds ``self.lower`` and ``self.upper`` (dim,) and
    ``self.options``, whose names they declare in ``OPTIONS``. One that holds a thread or a file releases
    it in ``close()``.

    Parameters
    ----------
    dim : int
        The number of variables (22 normalized materials in the benchmark).
    budget : int
        Evaluations allowed: ``ask`` never proposes more than remain.
    seed : int, default 0
        The seed of ``self.rng``.
    lower, upper : float or array_like of shape (dim,), default -1.0 and 1.0
        The box; every asked point is clipped into it.
    **options
        The calibrator's options, names from its ``OPTIONS``.

    Raises
    ------
    ValueError
        dim or budget below 1, or a bound not below its upper bound.
    OptionError
        An option the calibrator does not declare (the message lists those it does).

    See Also
    --------
    optimizers.registry.register : make a subclass available by name.
    minimize : the ask/evaluate/tell loop until the budget is spent.

    Examples
    --------
    >>> import numpy as np
    >>> from optimizers import make, minimize
    >>> opt = make("random", dim=3, budget=32, seed=0)
    >>> result = minimize(opt, lambda x: np.sum(x**2, axis=1))  # fun_batch: (k, dim) -> (k,)
    >>> result.nfev, result.history_x.shape
    (32, (32, 3))
    """

    name: str = ""
    OPTIONS: tuple[str, ...] = ()
    """The option names this calibrator reads (`self.options`)."""
    accepts_storage: bool = False
    """Whether it takes an Optuna `storage` and `study_name` (the benchmark then passes one per cell)."""

    def __init__(self, dim: int, budget: int, seed: int = 0, lower=-1.0, upper=1.0, **options):
        if dim < 1 or budget < 1:
            raise ValueError(f"dim and budget must be ≥ 1, but got dim={dim}, budget={budget}")
        self.dim, self.budget, self.seed = int(dim), int(budget), int(seed)
        self.lower = np.broadcast_to(np.asarray(lower, dtype=np.float64), (self.dim,)).copy()
        self.upper = np.broadcast_to(np.asarray(upper, dtype=np.float64), (self.dim,)).copy()
        if not np.all(self.lower < self.upper):
            raise ValueError(f"bounds must satisfy lower < upper, but got {self.lower} and {self.upper}")
        unknown = sorted(set(options) - set(self.OPTIONS))
        if unknown:
            raise OptionError(
                f"{self.name or type(self).__name__}: unknown option{'s' if len(unknown) > 1 else ''} "
                f"{', '.join(unknown)}; its options are: {', '.join(self.OPTIONS) or '(none)'}"
            )
        self.options = dict(options)
        self.rng = np.random.default_rng(self.seed)
        self._xs: list[np.ndarray] = []
        self._ys: list[float] = []
        self._pending = 0

    @property
    def nfev(self) -> int:
        return len(self._ys)

    @property
    def remaining(self) -> int:
        return self.budget - self.nfev

    @property
    def done(self) -> bool:
        return self.remaining <= 0 or self._stopped()

    def _stopped(self) -> bool:
        """True when the method has nothing more to propose (before the budget)."""
        return False

    def ask(self) -> np.ndarray:
        """A batch of points (k, dim) inside the bounds, k ≤ the remaining budget."""
        if self.done:
            raise RuntimeError(f"{self.name}: the budget of {self.budget} evaluations is spent")
        x = np.atleast_2d(np.asarray(self._ask(self.remaining), dtype=np.float64))
        if x.shape[1] != self.dim or not 1 <= len(x) <= self.remaining:
            raise RuntimeError(f"{self.name}: asked {x.shape}, but at most ({self.remaining}, {self.dim}) is allowed")
        x = np.clip(x, self.lower, self.upper)
        self._pending = len(x)
        return x

    def tell(self, x: ArrayLike, y: ArrayLike) -> None:
        """The values y (k,) of the points x (k, dim) last asked."""
        x = np.atleast_2d(np.asarray(x, dtype=np.float64))
        y = np.atleast_1d(np.asarray(y, dtype=np.float64))
        if len(x) != len(y) or len(x) != self._pending:
            raise ValueError(f"{self.name}: tell {len(y)} values for the {self._pending} points asked")
        y = np.where(np.isfinite(y), y, np.inf)
        self._pending = 0
        self._xs.extend(x)
        self._ys.extend(y.tolist())
        self._tell(x, y)

    def result(self) -> OptimizeResult:
        if not self._ys:
            raise RuntimeError(f"{self.name}: nothing evaluated yet")
        ys = np.array(self._ys)
        best = int(np.argmin(ys))
        stopped = self._stopped() and self.remaining > 0
        message = "the method converged before the budget" if stopped else f"budget of {self.budget} evaluations used"
        return OptimizeResult(
            np.array(self._xs[best]),
            float(ys[best]),
            self.nfev,
            bool(np.isfinite(ys[best])),
            message,
            np.array(self._xs),
            ys,
        )

    @abstractmethod
    def _ask(self, n_max: int) -> np.ndarray: ...

    def _tell(self, x: np.ndarray, y: np.ndarray) -> None:
        """Learn from the values y (k,) of x (k, dim); nothing by default (non-adaptive samplers)."""

    def close(self) -> None:
        """Release threads or files (nothing by default); the optimizer is not used afterwards."""

    def start_point(self) -> np.ndarray:
        """The `x0` option clipped into the box (dim,); without one, a draw from the prior (`prior_draw`)
        from `self.rng`, so that the start is where the seed puts it (a calibrator calls this once, in its
        constructor, before anything else draws from `self.rng`)."""
        x0 = self.options.get("x0")
        if x0 is None:
            return prior_draw(self.rng, self.lower, self.upper)
        return np.clip(np.broadcast_to(np.asarray(x0, dtype=np.float64), (self.dim,)), self.lower, self.upper)

    def choice(self, name: str, choices: tuple[str, ...]) -> str:
        """The option `name`, one of `choices` (default the first); a ValueError naming them if it is another."""
        value = self.options.get(name, choices[0])
        if value not in choices:
            raise ValueError(f"{name} must be {' or '.join(repr(c) for c in choices)}, but got {value!r}")
        return value


def prior_draw(rng: np.random.Generator, lower: np.ndarray, upper: np.ndarray) -> np.ndarray:
    """A point of the box [lower, upper] drawn from the population prior.

    Each coordinate is the box centre plus a normal of SD (upper − lower) / (2·SPAN_SD), truncated at
    ±SPAN_SD SD — Table 2's normals truncated as `table2.sample_materials` draws them, whose ±SPAN_SD SD span
    the box. On the benchmark's box of the 22 normalized materials, [-1, 1]^22, and a fresh
    `np.random.default_rng(seed)` it is exactly `table2.sample_materials(1, seed)[0]`.

    Parameters
    ----------
    rng : np.random.Generator
        The generator drawn from (advanced by the draw).
    lower, upper : np.ndarray, shape (dim,)
        The box's bounds.

    Returns
    -------
    np.ndarray, shape (dim,)
        The point drawn.
    """
    z = material_prior().rvs(size=(1, len(lower)), random_state=rng)[0]
    return 0.5 * (lower + upper) + 0.5 * (upper - lower) * z / SPAN_SD


def minimize(
    optimizer: Optimizer,
    fun_batch: Callable[[np.ndarray], ArrayLike],
    callback: Callable[[np.ndarray, np.ndarray], object] | None = None,
) -> OptimizeResult:
    """Drive a calibrator's ask/tell loop until its budget is spent or it stops.

    Parameters
    ----------
    optimizer : Optimizer
        A fresh calibrator (`optimizers.make`).
    fun_batch : callable
        The objective over a batch: points of shape (k, dim) to values of shape (k,). In the benchmark, one
        batched simulation of the calibration trial.
    callback : callable, optional
        ``callback(x, y)``, called after every batch (the benchmark logs the evaluations there).

    Returns
    -------
    OptimizeResult
        The best point, its value and every evaluation in order.
    """
    while not optimizer.done:
        x = optimizer.ask()
        y = np.asarray(fun_batch(x), dtype=np.float64)
        optimizer.tell(x, y)
        if callback is not None:
            callback(x, y)
    return optimizer.result()
