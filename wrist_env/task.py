"""One calibration task: a participant model, a capitate driver and the reference kinematics.

The thin layer between the environments (and the runners) and the solver:
designs in, rewards and JSON-ready outputs out. Simulation is `simulate` /
`simulate_batch`; the cost is `wrist_env.cost`; nothing is recomputed here.
"""

from __future__ import annotations

import functools
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike

from wrist_env import design as design_vars
from wrist_env.cost import COST_BONES, CostReport, CostWeights, kinematic_cost
from wrist_env.design import Design
from wrist_env.errors import DesignError, ParticipantError
from wrist_env.ligaments import ALL_LIGAMENT_NAMES
from wrist_env.model import BONES, PAIRS, Model
from wrist_env.motions import IDEALIZED, MOTIONS, TRIAL_MOTIONS
from wrist_env.participants import builtin, instances, registry
from wrist_env.solver.drivers import Driver, for_motion
from wrist_env.solver.forces import CONTACT_FIELDS
from wrist_env.solver.settings import DEFAULT_LOADS, LOAD_DIRECTIONS, SolverSettings
from wrist_env.solver.simulate import Result, prepare, simulate, simulate_batch

__all__ = [
    "Evaluation",
    "Evaluations",
    "REFERENCE_KEYS",
    "has_reference",
    "require_reference",
    "Task",
    "cost_poses",
    "outputs",
    "task",
]


@dataclass(frozen=True)
class Evaluation:
    """The outcome of one design.

    Parameters
    ----------
    reward : float
        −cost.
    cost : float
        The kinematic cost (0 without reference kinematics).
    failed : bool
        Whether the run or its cost failed.
    info : dict
        The outputs (`outputs`): deterministic and NaN-free.
    result : Result
        The simulation's result.
    """

    reward: float
    cost: float
    failed: bool
    info: dict
    result: Result


@dataclass(frozen=True)
class Evaluations(Sequence):
    """The outcomes of a batch of designs: each `Evaluation` by index, and arrays over the batch.

    The arrays are `reward` and `cost`, shape (n,), and `failed`, shape (n,) bool.

    Parameters
    ----------
    each : tuple of Evaluation
        The n outcomes, in the batch's order.
    """

    each: tuple[Evaluation, ...]
    reward: np.ndarray = field(init=False)
    cost: np.ndarray = field(init=False)
    failed: np.ndarray = field(init=False)

    def __post_init__(self):
        object.__setattr__(self, "reward", np.array([e.reward for e in self.each], dtype=np.float64))
        object.__setattr__(self, "cost", np.array([e.cost for e in self.each], dtype=np.float64))
        object.__setattr__(self, "failed", np.array([e.failed for e in self.each], dtype=bool))

    def __len__(self) -> int:
        return len(self.each)

    def __getitem__(self, i):
        return self.each[i]


REFERENCE_KEYS = ("cost", "error_p75", "rmse", "cost_terms")
"""The `info` entries scored against the reference kinematics: None where there is none (`has_reference`)."""


def has_reference(participant: str, motion: str) -> bool:
    """Whether the participant's motion has reference kinematics to score against.

    Found without building its model: a trial with the motion's role, or for "idealized" a built-in
    participant's hidden truth (a folder participant has none: its sweep's reward is 0 and its
    `REFERENCE_KEYS` are None).

    Parameters
    ----------
    participant : str
        A registered participant.
    motion : {"calibrate", "validate", "idealized"}
        A trial's role, or the idealized sweep.

    Returns
    -------
    bool
        Whether it has a reference.
    """
    if motion == IDEALIZED:
        return participant in builtin.BUILTIN
    return any(t.role == motion for t in registry.trials(participant).values())


def require_reference(participant: str, motion: str) -> None:
    """Check that the participant's motion has reference kinematics (`has_reference`).

    Parameters
    ----------
    participant : str
        A registered participant.
    motion : {"calibrate", "validate", "idealized"}
        The motion.

    Raises
    ------
    ParticipantError
        It has none, without which a study of costs and errors means nothing (the message names the
        participant, the motion and the motions that have one).
    """
    if not has_reference(participant, motion):
        usable = [m for m in MOTIONS if has_reference(participant, m)]
        why = (
            "only the built-in participants' sweeps have one, from their hidden truth"
            if motion == IDEALIZED
            else f"it has no trial with role {motion!r}"
        )
        raise ParticipantError(
            f"participant {participant!r} has no reference kinematics for the {motion} motion ({why}), so its "
            f"cost and DOF errors are undefined; motions with one: {usable}"
        )


class Task:
    """A participant's model, one motion's driver and its reference kinematics: designs in, rewards out.

    The one door from designs to rewards: the environments, the calibrators, the Monte Carlo study and
    the identification tools all score designs through a `Task`. It loads the model and prepares the
    solver's arrays once, so that each evaluation is a simulation and a cost.

    Parameters
    ----------
    participant : str
        A registered participant: a built-in (P1, P2, P3) or a folder's (`registry.add_folder`).
    motion : {"calibrate", "validate", "idealized"}, default "calibrate"
        The unresisted trial, the held-out resisted trial, or the idealized flexion–extension sweep. The
        sweep's reference is the hidden truth's sweep for a built-in participant, none for a folder's (its
        reward is then 0 and the info's `REFERENCE_KEYS` are None).
    settings : SolverSettings, optional
        The solver's settings (default `SolverSettings()`).
    weights : CostWeights, optional
        The cost's per-DOF weights (default 1 for every DOF).
    load_direction : str, default `settings.DEFAULT_LOADS`
        The loads' lines of action (`settings.LOAD_DIRECTIONS`): the sweep's, and in a trial the free
        bodies' (the capitate is prescribed) at the trial's recorded `load_n`.
    instance : int, default 0
        The problem instance of a built-in participant (`participants.instances`): 0 its shipped truth and
        trials, k ≥ 1 a truth drawn from the prior and the trials made from it.

    Attributes
    ----------
    model : Model
        The participant's built model.
    driver : Driver
        The motion's driver: the capitate's targets and the loads per frame.
    reference : ndarray of shape (2, n_frames, 4, 4) or None
        The scaphoid's and lunate's reference poses (RCS, mm); None without reference kinematics.
    truth : Design or None
        The instance's hidden truth (None for a folder participant).

    Raises
    ------
    ValueError
        An unknown motion or load direction (the message lists the valid ones).
    ParticipantError
        An unknown participant, or an instance k ≥ 1 of a folder participant.

    See Also
    --------
    task : the shared `Task` of default settings, one per participant, motion, load and instance.

    Examples
    --------
    >>> import numpy as np
    >>> from wrist_env import design
    >>> from wrist_env.task import Task
    >>> calibration = Task("P1", "calibrate")
    >>> evaluation = calibration.evaluate(design.population())
    >>> evaluation.reward == -evaluation.cost
    True
    >>> batch = calibration.evaluate_actions(np.zeros((4, 27)))  # one batched solver call
    >>> batch.cost.shape
    (4,)
    """

    def __init__(
        self,
        participant: str,
        motion: str = "calibrate",
        *,
        settings: SolverSettings | None = None,
        weights: CostWeights | None = None,
        load_direction: str = DEFAULT_LOADS,
        instance: int = 0,
    ):
        if motion not in MOTIONS:
            raise ValueError(f"motion must be one of {MOTIONS}, but got {motion!r}")
        if load_direction not in LOAD_DIRECTIONS:
            raise ValueError(f"load_direction must be one of {LOAD_DIRECTIONS}, but got {load_direction!r}")
        self.participant, self.motion, self.load_direction = participant, motion, load_direction
        self.settings, self.weights = settings, weights
        self.instance = instance
        if instance != 0 or participant in builtin.BUILTIN:
            self.problem: instances.Instance | None = instances.instance(participant, instance)
        else:
            self.problem = None
        self.truth: Design | None = None if self.problem is None else self.problem.truth
        self.model: Model = registry.load_model(participant)
        self.driver, self.reference = self._driver_and_reference()
        self.prepared = prepare(self.model, settings, self.driver.mode)
        self.reference_points = self.model.centroid[[BONES.index(b) for b in COST_BONES]]

    def _driver_and_reference(self) -> tuple[Driver, np.ndarray | None]:
        """The motion's driver (`drivers.for_motion`) and its reference kinematics of the cost bones: the trial's
        poses, the hidden truth's sweep, or None (a user participant's sweep)."""
        trial = None
        if self.motion in TRIAL_MOTIONS:
            trial = (
                registry.trial(self.participant, self.motion)
                if self.problem is None
                else self.problem.trial(self.motion)
            )
        driver = for_motion(self.model, self.motion, trial, direction=self.load_direction)
        if trial is not None:
            return driver, np.stack([trial.pose(b) for b in COST_BONES])
        if not has_reference(self.participant, self.motion):
            return driver, None
        truth = simulate(self.model, self.truth, driver, self.settings)
        return driver, cost_poses(truth.poses)

    def evaluate(self, design: Design) -> Evaluation:
        """Simulate one design and score it."""
        return self._score(design, simulate(self.model, design, self.driver, prepared=self.prepared))

    def evaluate_batch(self, designs: Iterable[Design]) -> Evaluations:
        """Simulate many designs at once (`simulate_batch`: one thread per core); the same numbers as one at a time.

        No designs: empty `Evaluations` (reward, cost and failed of shape (0,)), nothing simulated, as a batch
        filtered down to nothing is still a batch. `DesignError` naming the item if one is not a `Design`."""
        designs = list(designs)
        for i, d in enumerate(designs):
            if not isinstance(d, Design):
                raise DesignError(
                    f"item {i} of the designs is a {type(d).__name__}, not a Design (actions: evaluate_actions)"
                )
        if not designs:
            return Evaluations(())
        results = simulate_batch(self.model, designs, self.driver, prepared=self.prepared)
        return Evaluations(tuple(self._score(d, r) for d, r in zip(designs, results)))

    def evaluate_action(self, action: ArrayLike) -> Evaluation:
        """Simulate and score one normalized action (27,) in [-1, 1] (`design.from_action`)."""
        return self.evaluate(design_vars.from_action(action))

    def evaluate_actions(self, actions: ArrayLike) -> Evaluations:
        """`evaluate_batch` of normalized actions (n, 27) in [-1, 1] (`design.from_actions`); shape (0, 27)
        gives empty `Evaluations`, any other shape a `DesignError` naming it."""
        return self.evaluate_batch(design_vars.from_actions(actions))

    def _score(self, design: Design, result: Result) -> Evaluation:
        if self.reference is None:
            cost, report = 0.0, None
        else:
            report = kinematic_cost(
                cost_poses(result.poses), self.reference, reference_points=self.reference_points, weights=self.weights
            )
            cost = float(report.total)
        failed = not result.ok or (report is not None and report.failed)
        return Evaluation(-cost, cost, failed, outputs(result, report), result)


def cost_poses(poses: np.ndarray) -> np.ndarray:
    """The cost's bones' poses of a simulation's poses.

    Parameters
    ----------
    poses : np.ndarray, shape (n_frames, n_bodies, 4, 4)
        Every body's poses, RCS, mm.

    Returns
    -------
    np.ndarray, shape (2, n_frames, 4, 4)
        The poses of `cost.COST_BONES` (scaphoid, lunate).
    """
    return np.stack([poses[:, BONES.index(b)] for b in COST_BONES])


def outputs(result: Result, report: CostReport | None = None) -> dict:
    """JSON-ready, NaN-free per-frame outputs and the cost's `REFERENCE_KEYS`.

    Parameters
    ----------
    result : Result
        The simulation's result; a failed run's arrays are zeros, `failed` True.
    report : CostReport, optional
        The cost; without one (no reference kinematics) the `REFERENCE_KEYS` are None: the same keys for
        every participant, and no value taken for a score (0 reads as a perfect fit; NaN breaks JSON).

    Returns
    -------
    dict
        The info of an `Evaluation`: status, poses, contact, bundle forces, energies, steps and the cost's.
    """

    def clean(a):
        return np.nan_to_num(np.asarray(a, dtype=np.float64), nan=0.0)

    contact, bundle, energy = clean(result.contact), clean(result.bundle_force), clean(result.energy)
    info = {
        "failed": not result.ok,
        "status": result.message,
        "poses": clean(result.poses),
        "contact": {
            pair: {field: contact[:, p, k] for k, field in enumerate(CONTACT_FIELDS)} for p, pair in enumerate(PAIRS)
        },
        "bundle_force_n": {lig: bundle[:, i] for i, lig in enumerate(ALL_LIGAMENT_NAMES)},
        "kinetic_energy_nmm": energy[:, 0],
        "internal_energy_nmm": energy[:, 1],
        "steps": np.asarray(result.steps, dtype=np.int64),
        "settled": np.asarray(result.settled, dtype=bool),
    }
    info |= dict.fromkeys(REFERENCE_KEYS)
    if report is not None:
        r = report.to_dict()
        info["cost"] = r["total"]
        info["failed"] = info["failed"] or r["failed"]
        info["error_p75"] = _zero_undefined(r["error_p75"])
        info["rmse"] = _zero_undefined(r["rmse"])
        info["cost_terms"] = _zero_undefined(r["terms"])
    return info


def _zero_undefined(per_bone: dict) -> dict:
    """{bone: {DOF: value}} with a failed run's undefined (None) values as 0, as its arrays are."""
    return {b: {dof: 0.0 if v is None else v for dof, v in dofs.items()} for b, dofs in per_bone.items()}


@functools.lru_cache(maxsize=32)
def task(participant: str, motion: str, load_direction: str = DEFAULT_LOADS, instance: int = 0) -> Task:
    """The shared `Task` of a participant's motion, with default solver settings and cost weights.

    Models and their prepared arrays are large, so one `Task` per (participant, motion, load direction,
    instance) is made and kept (the 32 most recent): the environments and `calibrate` use it.

    Parameters
    ----------
    participant : str
        A registered participant's name.
    motion : {"calibrate", "validate", "idealized"}
        The motion (`motions.MOTIONS`).
    load_direction : str, default `settings.DEFAULT_LOADS`
        The loads' lines of action (`settings.LOAD_DIRECTIONS`).
    instance : int, default 0
        The problem instance of a built-in participant (`participants.instances`).

    Returns
    -------
    Task
        The same object for the same arguments.

    Examples
    --------
    >>> from wrist_env.task import task
    >>> task("P1", "calibrate") is task("P1", "calibrate")
    True
    """
    return Task(participant, motion, load_direction=load_direction, instance=instance)
