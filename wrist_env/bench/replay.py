"""Resume by replay: a fresh calibrator, told a cell's logged evaluations again without simulating them.

A benchmark cell cut short keeps its evaluations in the run log. To resume it, a fresh calibrator with
the same seed is wrapped in `Replayed`: while logged evaluations remain, each batch the calibrator asks
for must equal the logged points (within `REPLAY_TOLERANCE`), and it is told their logged values (the
objective column: the MAP objective of a ``+prior`` calibrator, else the cost). Then the wrapper passes
every ask and tell through, so the run continues where it stopped as if never cut. A calibrator that
asks otherwise (it ignores its seed), asks past the end of the log or stops before it, cannot resume:
`ResumeError`, naming the cell.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from optimizers.base import Optimizer, OptimizeResult
from wrist_env.bench.schema import X_COLUMNS
from wrist_env.errors import WristEnvError

if TYPE_CHECKING:
    import pandas as pd

REPLAY_TOLERANCE = 1e-9
"""Largest |asked − logged| (normalized units) accepted when replaying a logged batch."""


class ResumeError(WristEnvError, RuntimeError):
    """A calibrator did not ask again for the points it asked before (it is not deterministic).

    Raised when a cell cut short is resumed by replay (`Replayed`) and the fresh calibrator, seeded as the
    logged run, asks for points other than the logged ones, stops before the logged evaluations are
    replayed, or the log holds more evaluations than the budget.
    """


@dataclass(frozen=True)
class Logged:
    """A cell's logged evaluations, in order: what a resume replays.

    x: (n, dim) the logged points; y: (n,) the values the calibrator was told (the objective column,
    the cost where it is null); batches: the next free batch number (the largest logged one + 1).
    """

    x: np.ndarray
    y: np.ndarray
    batches: int

    @classmethod
    def of(cls, frame: pd.DataFrame | None, dim: int) -> Logged:
        """The evaluations of a cell's rows (`RunLog.read_cell`); none for None (nothing logged)."""
        if frame is None:
            return cls(np.empty((0, dim)), np.empty(0), 0)
        y = frame["objective"].fillna(frame["cost"]).to_numpy()
        return cls(frame[list(X_COLUMNS)].to_numpy(), y, int(frame["batch"].max()) + 1)


class Replayed(Optimizer):
    """A calibrator resumed from its logged evaluations: replayed on construction, then passed through.

    Constructing it replays `logged` into `calibrator` (a fresh one, with the seed of the logged run):
    each asked batch is checked against the logged points and told the logged values, and
    ``on_batch(x, y)``, if given, is called after each such batch (as `minimize`'s callback would be).
    Afterwards `ask`, `tell`, `done`, `result` and `close` are the calibrator's, so `minimize` runs on
    from the first evaluation not logged. ``replayed`` counts the evaluations taken from the log.

    Raises `ResumeError` naming `cell` when more evaluations are logged than the budget, when an asked
    batch differs from the logged points or reaches past them, or when the calibrator stops first.
    """

    def __init__(
        self,
        calibrator: Optimizer,
        logged: Logged,
        cell: str,
        on_batch: Callable[[np.ndarray, np.ndarray], object] | None = None,
    ):
        super().__init__(calibrator.dim, calibrator.budget, calibrator.seed, calibrator.lower, calibrator.upper)
        self.name = calibrator.name
        self.calibrator = calibrator
        n_logged = len(logged.y)
        if n_logged > calibrator.budget:
            raise ResumeError(f"{cell}: {n_logged} evaluations are logged, more than the budget {calibrator.budget}")
        n = 0
        while n < n_logged and not calibrator.done:
            x = calibrator.ask()
            k = len(x)
            if n + k > n_logged or np.max(np.abs(x - logged.x[n : n + k])) > REPLAY_TOLERANCE:
                raise ResumeError(
                    f"{cell}: on resume the calibrator asked for evaluations {n}…{n + k - 1} differently than "
                    f"logged ({n_logged} logged); it is not deterministic for a seed, so this cell cannot "
                    f"resume: delete its files from the run log to start it over"
                )
            y = logged.y[n : n + k]
            calibrator.tell(x, y)
            n += k
            if on_batch is not None:
                on_batch(x, y)
        if n < n_logged:
            raise ResumeError(f"{cell}: the calibrator stopped after {n} evaluations, but {n_logged} are logged")
        self.replayed = n

    @property
    def nfev(self) -> int:
        return self.calibrator.nfev

    @property
    def done(self) -> bool:
        return self.calibrator.done

    def ask(self) -> np.ndarray:
        return self.calibrator.ask()

    def tell(self, x: ArrayLike, y: ArrayLike) -> None:
        self.calibrator.tell(x, y)

    def result(self) -> OptimizeResult:
        return self.calibrator.result()

    def _ask(self, n_max: int) -> np.ndarray:
        return self.calibrator._ask(n_max)

    def close(self) -> None:
        self.calibrator.close()
