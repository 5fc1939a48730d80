"""What the benchmark's run log holds: a cell's key (`RunKey`), the evaluation rows' columns (`SCHEMA`) and
the fields of a cell's summary (`SUMMARY_KEYS`) — the vocabulary `RunLog` (`bench.log`) writes and the
leaderboard, the IOHanalyzer export and the calibrations read.

A row is one evaluation: the run key (participant, optimizer, seed,
budget, instance: the problem instance, `participants.instances`; a log written before instances reads as
instance 0), its index in the run (`eval`, 0-based, the optimizer's order) and
batch (`batch`), the 22 normalized material variables (`x.<name>`), the
kinematic cost on the calibration trial, `failed`, the RMSE of the 12
scaphoid and lunate DOF (`rmse.<bone>.<DOF>`, mm and deg; NaN if failed),
the `objective` the calibrator minimized (the cost, or the MAP objective), and
`unsettled`, the frames whose hold ran out before equilibrium (null if failed).
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import pyarrow as pa
import pyarrow.compute as pc

from wrist_env.cost import COST_BONES
from wrist_env.design import N_MATERIAL, NAMES
from wrist_env.errors import StoreError, WristEnvError
from wrist_env.frames import DOF_NAMES
from wrist_env.limits import MAX_BUDGET, MAX_INSTANCE, MAX_SEED, check_int
from wrist_env.motions import TRIAL_MOTIONS

KEY_FIELDS = ("participant", "optimizer", "seed", "budget", "instance")
X_COLUMNS = tuple(f"x.{n}" for n in NAMES[:N_MATERIAL])
RMSE_COLUMNS = tuple(f"rmse.{bone}.{dof}" for bone in COST_BONES for dof in DOF_NAMES)
SCHEMA = pa.schema(
    [
        ("participant", pa.string()),
        ("optimizer", pa.string()),
        ("seed", pa.int64()),
        ("budget", pa.int64()),
        ("instance", pa.int64()),
        ("eval", pa.int64()),
        ("batch", pa.int64()),
        ("time", pa.float64()),
    ]
    + [(c, pa.float64()) for c in X_COLUMNS]
    + [("cost", pa.float64()), ("failed", pa.bool_())]
    + [(c, pa.float64()) for c in RMSE_COLUMNS]
    + [("objective", pa.float64()), ("unsettled", pa.int64())]
)
"""Columns of the evaluation log; `time` is the Unix time the batch finished; `objective` is the value
the calibrator was told (the cost, or a `+prior` calibrator's MAP objective); `unsettled` the frames of
the run whose hold ran out before equilibrium (its outputs are where the bones were then; null if the
run failed). Both are null in logs older than them. `instance` is the problem instance (`RunKey.instance`);
`RunLog` reads it as 0 in logs older than it."""

SUMMARY_KEYS = (
    "participant",
    "optimizer",
    "seed",
    "budget",
    "nfev",
    "best_cost",
    "best_eval",
    "calibrate",
    "validate",
    "recovery_z",
    "recovery_z_population",
)
"""Fields of a cell summary the leaderboard reads; `calibrate` and `validate` hold `SCORE_KEYS`. A summary also
records its `instance`, read as 0 where it does not (`summary_instance`: written before instances)."""
SCORE_KEYS = ("cost", "failed", "rmse")

RERUN = "rerun the benchmark command (same arguments) to redo it"


def check_summary(path: Path, summary) -> None:
    """`StoreError` naming `path` if `summary` lacks a field the leaderboard reads."""
    if not isinstance(summary, dict):
        raise StoreError(f"{path}: not a cell summary (a JSON {type(summary).__name__}); {RERUN}")
    missing = [k for k in SUMMARY_KEYS if k not in summary]
    for t in TRIAL_MOTIONS:
        if t in summary:
            missing += [f"{t}.{k}" for k in SCORE_KEYS if not isinstance(summary[t], dict) or k not in summary[t]]
    nfev = summary.get("nfev")
    if not isinstance(nfev, int) or isinstance(nfev, bool):
        missing.append("an integer nfev")
    if missing:
        raise StoreError(f"{path}: not a whole cell summary (no {', '.join(missing)}); {RERUN}")


def describe_problem(participant: str, instance: int) -> str:
    """A problem in words: "P1" for instance 0, "P1 instance 3" for instance 3."""
    return participant if instance == 0 else f"{participant} instance {instance}"


def summary_instance(summary: dict) -> int:
    """The problem instance a cell summary (or a row) records; 0 for one written before instances."""
    instance = summary.get("instance")
    return 0 if instance is None else instance


def key_of(summary: dict) -> RunKey:
    """The `RunKey` of a cell summary or a row (instance 0 where it records none); `WristEnvError`,
    `KeyError` or `TypeError` if its fields are not a key."""
    return RunKey(**{k: summary[k] for k in KEY_FIELDS if k != "instance"}, instance=summary_instance(summary))


def summary_cell(summary: dict) -> str:
    """The cell name the key fields of a summary (or a row) give (`RunKey.name`), or a description if they
    are not a key."""
    try:
        return key_of(summary).name
    except (WristEnvError, KeyError, TypeError, ValueError):
        return f"{[summary.get(k) for k in KEY_FIELDS]} (not a cell key)"


@dataclass(frozen=True, order=True)
class RunKey:
    """One benchmark cell: a calibrator run on a problem instance of a participant with a seed and a budget.

    Parameters
    ----------
    participant : str
        The participant's name.
    optimizer : str
        The calibrator's name, optionally with ``+prior``.
    seed : int
        The calibrator's seed, in [0, `limits.MAX_SEED`].
    budget : int
        Evaluations allowed, in [1, `limits.MAX_BUDGET`].
    instance : int, default 0
        The problem instance (`participants.instances`; 0, the default, its shipped truth and trials), in
        [0, `limits.MAX_INSTANCE`].

    Raises
    ------
    InputError
        seed, budget or instance not an int in its range (the message names the field, range and value).
    """

    participant: str
    optimizer: str
    seed: int
    budget: int
    instance: int = 0

    def __post_init__(self):
        check_int("seed", self.seed, 0, MAX_SEED)
        check_int("budget", self.budget, 1, MAX_BUDGET)
        check_int("instance", self.instance, 0, MAX_INSTANCE)

    @property
    def name(self) -> str:
        """A file-name-safe identifier, also the Optuna study name: `P1.cmaes.seed3.budget300` on instance 0
        (as before instances, so older logs and studies keep their names), `P1.i3.cmaes.seed3.budget300`
        on instance 3."""
        problem = self.participant if self.instance == 0 else f"{self.participant}.i{self.instance}"
        safe = re.sub(r"[^A-Za-z0-9_.+-]", "_", f"{problem}.{self.optimizer}")
        return f"{safe}.seed{self.seed}.budget{self.budget}"

    @property
    def problem(self) -> str:
        """The problem in words: the participant, and its instance unless 0 (`describe_problem`)."""
        return describe_problem(self.participant, self.instance)

    def as_dict(self) -> dict:
        return {
            "participant": self.participant,
            "instance": self.instance,
            "optimizer": self.optimizer,
            "seed": self.seed,
            "budget": self.budget,
        }


def with_instance(table: pa.Table) -> pa.Table:
    """`table` with its null `instance` (a file written before instances: pyarrow reads a missing column as
    nulls) as instance 0."""
    column = table.column("instance")
    if column.null_count == 0:
        return table
    filled = pc.fill_null(column, 0)
    return table.set_column(table.schema.get_field_index("instance"), "instance", filled)
