"""Calibrate one participant with one calibrator: the benchmark's unit of work (a cell).

The search space is the 22 material variables (normalized, [-1, 1]); the
five injury scalars are frozen intact (action = concat(x, ones(5)), as
`FreezeVariables` does). Each batch the calibrator asks for is one batched
solver call on the calibration trial (`Task("calibrate").evaluate_batch`);
the kinematic cost is the value. Any calibrator's name with `+prior`
appended (`cmaes+prior`) minimizes the MAP objective instead: the kinematic
misfit in units of the 4DCT noise plus the population prior
(`posterior.map_objective`); the log keeps both its cost and its objective.
The best design is then scored on the held-out resisted trial ("validate")
and, for built-in participants, against the hidden truth (parameter recovery
in Table 2 SD units). On a problem instance k (`instance=k`, `participants.instances`) the trials are
instance k's and the truth is instance k's draw (`Task.truth`); instance 0 is the shipped problem.

With a run log, every batch is logged as it finishes (`BatchLog`), and a cell
that was cut short resumes: its logged evaluations are replayed into a fresh
calibrator with the same seed (`bench.replay.Replayed`: each asked batch must
equal the logged points; their logged values are told without simulating),
then the run continues.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

import optimizers
from optimizers.optuna_storage import open_url
from wrist_env import design as design_vars
from wrist_env import table2
from wrist_env.bench.log import RunLog
from wrist_env.bench.replay import REPLAY_TOLERANCE as REPLAY_TOLERANCE  # `X as X`: re-exported from here
from wrist_env.bench.replay import Logged, Replayed
from wrist_env.bench.replay import ResumeError as ResumeError
from wrist_env.bench.schema import RunKey
from wrist_env.bench.scoring import recovery_error as recovery_error
from wrist_env.bench.scoring import rmse_vector, score, unsettled_frames
from wrist_env.design import N_MATERIAL, Design
from wrist_env.identification.likelihood import map_objective
from wrist_env.runs import provenance
from wrist_env.task import Task, task

if TYPE_CHECKING:
    from optuna.storages import BaseStorage

PRIOR_SUFFIX = "+prior"
"""Appended to a calibrator's name: the same calibrator on the MAP objective (kinematic misfit + prior)."""


def action(x: ArrayLike) -> np.ndarray:
    """The 27-variable action(s) of 22 normalized materials (..., 22), injury scalars intact (+1)."""
    return design_vars.full_action(x)


def split_prior(name: str) -> tuple[str, bool]:
    """(registered calibrator name, whether it minimizes the MAP objective) of a benchmark calibrator name."""
    if name.endswith(PRIOR_SUFFIX):
        return name[: -len(PRIOR_SUFFIX)], True
    return name, False


def accepts_storage(cls) -> bool:
    """Whether a calibrator class takes an Optuna `storage` option (its `accepts_storage` attribute)."""
    return bool(getattr(cls, "accepts_storage", False))


@dataclass
class CalibrationRun:
    """One calibration: the calibrator's result, the calibrated design and how good it is.

    Parameters
    ----------
    key : RunKey
        The cell: participant, calibrator, seed, budget and instance.
    result : OptimizeResult
        The calibrator's result (``x`` of shape (22,): the best 22 normalized materials).
    design : Design
        The calibrated design (injury intact); ``design.as_dict()`` in physical units.
    calibrate : dict
        ``{"cost", "failed", "rmse", "error_p75", "unsettled_frames"}`` of the calibrated design on the
        calibration trial (rmse, error_p75: ``{bone: {DOF: mm or deg}}``; unsettled_frames: frames whose
        hold ran out before equilibrium, None if failed).
    validate : dict
        The same on the held-out resisted trial.
    recovery_z : float or None
        RMS of z(calibrated) − z(truth) over the 22 materials (Table 2 SD units); None without a hidden
        truth.
    recovery_z_population : float or None
        The same for the population design.
    best_eval : int
        The 0-based index of the best evaluation in the run.
    replayed : int
        Evaluations taken from the log instead of simulated (a resumed run).
    wall_seconds : float
        Wall time of the calibration, s.
    options : dict, default {}
        The calibrator's options the run was made with.

    Attributes
    ----------
    cost : float
        ``calibrate["cost"]``, the calibrated design's cost on the calibration trial.
    validate_cost : float
        ``validate["cost"]``, its cost on the held-out trial.
    """

    key: RunKey
    result: object
    design: Design
    calibrate: dict
    validate: dict
    recovery_z: float | None
    recovery_z_population: float | None
    best_eval: int
    replayed: int
    wall_seconds: float
    options: dict = field(default_factory=dict)

    @property
    def cost(self) -> float:
        return self.calibrate["cost"]

    @property
    def validate_cost(self) -> float:
        return self.validate["cost"]

    def to_dict(self, *, history: bool = False) -> dict:
        """JSON-ready summary (what the run log keeps per finished cell)."""
        r = self.result
        prior = split_prior(self.key.optimizer)[1]
        out = dict(self.key.as_dict())
        out.update(
            {
                "nfev": int(r.nfev),
                "success": bool(r.success),
                "message": r.message,
                "best_eval": self.best_eval,
                "objective": "map" if prior else "cost",
                "best_objective": float(r.fun),
                "best_cost": self.calibrate["cost"] if prior else float(r.fun),
                "x": [float(v) for v in r.x],
                "design": self.design.as_dict(),
                "z_scores": dict(zip(design_vars.NAMES[:N_MATERIAL], table2.z_scores(self.design).tolist())),
                "calibrate": self.calibrate,
                "validate": self.validate,
                "recovery_z": self.recovery_z,
                "recovery_z_population": self.recovery_z_population,
                "replayed": self.replayed,
                "wall_seconds": round(self.wall_seconds, 3),
                "options": {
                    k: v for k, v in self.options.items() if isinstance(v, (str, int, float, bool, type(None)))
                },
            }
        )
        if history:
            out["history_fun"] = [float(v) for v in r.history_fun]
        return out


def calibrator_options(cls, study_name: str, storage: str | BaseStorage | None, options: dict | None) -> dict:
    """The options a cell's calibrator is made with: `options`, plus, for one that takes an Optuna storage
    (and given one), the storage and the cell's study name, its study deleted first: the run log is the
    record, and the replay of a resume rebuilds the study from it."""
    options = dict(options or {})
    if storage is not None and accepts_storage(cls):
        import optuna

        storage_obj = open_url(storage) if isinstance(storage, str) else storage
        try:
            optuna.delete_study(study_name=study_name, storage=storage_obj)
        except KeyError:
            pass
        options.update(storage=storage_obj, study_name=study_name)
    return options


@dataclass(frozen=True)
class Simulated:
    """One batch simulated on the calibration trial: the values told (`objective`: the cost, or the MAP
    objective for a ``+prior`` calibrator) and what the log keeps of each evaluation besides."""

    objective: np.ndarray
    cost: np.ndarray
    failed: np.ndarray
    rmse: np.ndarray
    unsettled: list


def simulate(calibration: Task, x: np.ndarray, prior: bool) -> Simulated:
    """Evaluate a batch of normalized materials (k, 22) in one batched simulation of the calibration trial."""
    designs = [design_vars.from_action(a) for a in action(x)]
    evaluations = calibration.evaluate_batch(designs)
    cost = evaluations.cost
    objective = cost
    if prior:
        objective = np.array([map_objective(calibration, e, table2.z_scores(d)) for e, d in zip(evaluations, designs)])
    rmse = np.stack([rmse_vector(e.info) for e in evaluations])
    return Simulated(objective, cost, evaluations.failed, rmse, [unsettled_frames(e) for e in evaluations])


class BatchLog:
    """A cell's evaluation and its logging, batch by batch, for `minimize` (`evaluate`, then `told` as its
    callback) and for a replay (`replayed`, as its `on_batch`).

    Batches are numbered in the order asked; the first one simulated after a replay takes the next free
    number of the log (`first_new`) if that is higher. Without a run log nothing is written.
    ``callback(n_new, nfev)`` is called after every batch, n_new 0 for a replayed one.
    """

    def __init__(
        self,
        calibration: Task,
        prior: bool,
        run_log: RunLog | None,
        key: RunKey,
        first_new: int,
        made_from: dict | None = None,
        callback: Callable[[int, int], object] | None = None,
    ):
        self.calibration, self.prior, self.run_log, self.key = calibration, prior, run_log, key
        self.first_new, self.made_from, self.callback = first_new, made_from, callback
        self.nfev = self.batch = 0
        self.pending: Simulated | None = None

    def evaluate(self, x: np.ndarray) -> np.ndarray:
        """The values of a batch asked, simulated (kept until `told` logs them)."""
        self.pending = simulate(self.calibration, x, self.prior)
        return self.pending.objective

    def told(self, x: np.ndarray, y: np.ndarray) -> None:
        """Log the batch just simulated and told."""
        self.batch = max(self.batch, self.first_new)
        if self.run_log is not None:
            p = self.pending
            self.run_log.append(
                self.key, self.batch, self.nfev, x, p.cost, p.failed, p.rmse, y, p.unsettled, self.made_from
            )
        self._counted(len(x), len(x))

    def replayed(self, x: np.ndarray, y: np.ndarray) -> None:
        """Count a batch replayed from the log (nothing simulated, nothing written)."""
        self._counted(len(x), 0)

    def _counted(self, k: int, n_new: int) -> None:
        self.batch += 1
        self.nfev += k
        if self.callback is not None:
            self.callback(n_new, self.nfev)


def calibrate(
    participant: str,
    optimizer_name: str,
    budget: int,
    seed: int,
    *,
    log: RunLog | str | Path | None = None,
    storage: str | BaseStorage | None = None,
    options: dict | None = None,
    callback: Callable[[int, int], object] | None = None,
    made_from: dict | None = None,
    instance: int = 0,
) -> CalibrationRun:
    """Calibrate the 22 ligament materials of a participant with one calibrator: one benchmark cell.

    The search space is the 22 normalized materials in [-1, 1]^22 (the injury scalars frozen intact);
    each batch the calibrator asks for is one batched simulation of the calibration trial, and the
    kinematic cost is the value minimized (the MAP objective for a name ending in ``+prior``). The best
    design is then scored on the held-out trial and, for a built-in participant, against its hidden truth.

    Parameters
    ----------
    participant : str
        A registered participant's name.
    optimizer_name : str
        A registered calibrator (`optimizers.available()`), optionally with ``+prior`` appended.
    budget : int
        Evaluations (simulations of the calibration trial) the calibrator may spend.
    seed : int
        The calibrator's seed: the same seed gives the same run.
    log : RunLog or path, optional
        A run log or its directory: every batch is logged as it finishes, and a cell cut short resumes
        from it by replay (see the module doc).
    storage : str or optuna storage, optional
        An Optuna storage given (with the cell's key as study name) to calibrators that take one; ignored
        by the others. Its study is rebuilt from the log on every start.
    options : dict, optional
        Extra options for the calibrator (`optimizers.make(..., **options)`).
    callback : callable, optional
        ``callback(n_new, nfev)``, called after every batch with the number of new evaluations.
    made_from : dict, optional
        The instance's `provenance.of_participant`, if the caller has it (else read here when there is
        a log).
    instance : int, default 0
        The problem instance (`participants.instances`): its calibrate trial is the objective, its validate
        trial the held-out score and its hidden truth what recovery is measured against (0: the shipped
        problem; k ≥ 1 only for built-in participants).

    Returns
    -------
    CalibrationRun
        ``result`` (the calibrator's `OptimizeResult`: ``x`` of shape (22,), ``history_fun`` of shape
        (budget,)), ``design`` (the calibrated `Design`), ``calibrate`` and ``validate`` (cost, failed, RMSE
        and 75th-percentile errors per bone and DOF, mm and deg), ``recovery_z`` (RMS distance to the
        hidden truth over the 22 materials, Table 2 SD units; None without a truth).

    Raises
    ------
    UnknownOptimizerError
        `optimizer_name` is not registered (the message lists the ones that are).
    ParticipantError
        An unknown participant, or an instance k ≥ 1 of a folder participant.
    ResumeError
        A logged cell the calibrator does not replay (it is not deterministic for its seed).

    Examples
    --------
    >>> from wrist_env.bench import calibrate
    >>> run = calibrate("P3", "cmaes", budget=24, seed=0)
    >>> run.result.history_fun.shape, run.result.x.shape
    ((24,), (22,))
    >>> run.design.as_dict()["SLIL_d.stiffness"]  # N/mm  # doctest: +SKIP
    """

    start_time = time.perf_counter()
    key = RunKey(participant, optimizer_name, int(seed), int(budget), instance)
    run_log = None if log is None else (log if isinstance(log, RunLog) else RunLog(Path(log)))
    base_name, prior = split_prior(optimizer_name)
    options = calibrator_options(optimizers.get(base_name), key.name, storage, options)
    calibration = task(participant, "calibrate", instance=instance)
    if run_log is not None:
        made_from = made_from or provenance.of_participant(participant, instance)
        run_log.move_aside_stale(key, made_from)  # another model's evaluations are not replayed
    logged = Logged.of(None if run_log is None else run_log.read_cell(key), N_MATERIAL)

    batches = BatchLog(calibration, prior, run_log, key, logged.batches, made_from, callback)
    calibrator = optimizers.make(base_name, dim=N_MATERIAL, budget=budget, seed=seed, **options)
    try:
        resumed = Replayed(calibrator, logged, key.name, on_batch=batches.replayed)
        result = optimizers.minimize(resumed, batches.evaluate, batches.told)
    finally:
        calibrator.close()

    run = CalibrationRun(
        key,
        result,
        **score(result, calibration, task(participant, "validate", instance=instance)),
        replayed=resumed.replayed,
        wall_seconds=time.perf_counter() - start_time,
        options={k: v for k, v in options.items() if k not in ("storage",)},
    )
    if run_log is not None:
        run_log.compact(key)
        run_log.write_summary(key, run.to_dict(history=False), made_from)
    return run
