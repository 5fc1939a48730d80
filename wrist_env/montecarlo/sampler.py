"""The Monte Carlo sampler: seeded Latin-hypercube blocks of designs, run through the Idealized environment.

Draws (preprint 2.3.2; the distributions are `monte_carlo_actions`):
a participant's runs come in blocks; block b is a Latin hypercube over all 27
variables of its own size, seeded by `block_seed(seed, participant, b)` —
a `numpy.random.SeedSequence` of the study seed with the spawn key
(CRC-32 of the participant's name, b) — so every draw, first or
replacement, is a pure function of (seed, participant, block, size).
Materials come from Table 2's normals truncated at ±3 SD by inverse CDF;
each injurable ligament is torn (action −0.5) with probability 0.3, else
intact (+1), independently.

Simulation: `run_chunk` evaluates the chunk's k designs with the participant's
Idealized task (`wrist_env.task.task(participant, "idealized")`), in one
`Task.evaluate_batch` call — the one the environments, the benchmark and
sensitivity make — and reads every per-run output from the evaluations'
`info` (per-frame contact per pair, bundle forces, status). The wrist angle
of each frame is the task's driver's (`task.driver.angle_deg`: the
capitate's prescribed flexion, flexion +, extension −).

Exclusion (preprint 2.3.2: "models with contact pressures exceeding 16.5 MPa
yielded unrealistic simulations"): a run is excluded when its radioscaphoid
mean pressure (the pair's mean over its contacting area) exceeds
`EXCLUDE_ABOVE_MPA` at any frame of the sweep. We read the preprint's
"contact pressures exceeding" as the curve crossing the line somewhere (it
was found "upon visual inspection" of the runs), not the sweep's average;
the log keeps every frame, so the other reading can be recomputed from it.
"""

from __future__ import annotations

import zlib
from collections.abc import Iterable
from typing import TYPE_CHECKING

import numpy as np
import pyarrow as pa
from numpy.typing import ArrayLike

from wrist_env import design
from wrist_env.design import N_DESIGN, N_MATERIAL, NAMES, SPAN_SD
from wrist_env.errors import DesignError
from wrist_env.ligaments import INJURABLE, LIGAMENT_NAMES
from wrist_env.montecarlo.config import EXCLUDE_ABOVE_MPA, TEAR_PROBABILITY
from wrist_env.participants import registry
from wrist_env.solver.settings import DEFAULT_LOADS
from wrist_env.table2 import material_prior
from wrist_env.task import task

if TYPE_CHECKING:
    from pathlib import Path


TORN_ACTION, INTACT_ACTION = -0.5, 1.0
"""Normalized injury scalars the Monte Carlo study gives a torn and an intact ligament."""


def monte_carlo_from_unit(
    u: ArrayLike, *, tear_probability: float = TEAR_PROBABILITY, truncate_sd: float = SPAN_SD
) -> np.ndarray:
    """Normalized actions of shape (n, 27) from points `u` of shape (n, 27) in [0, 1).

    Materials (the first 22 columns): Table 2's normals truncated at ± `truncate_sd` by
    inverse CDF, in action units (z / SPAN_SD). Injury scalars (the last 5): torn
    (`TORN_ACTION`) where u < `tear_probability`, else intact (`INTACT_ACTION`).
    """
    u = np.asarray(u, dtype=np.float64)
    if u.ndim != 2 or u.shape[1] != N_DESIGN:
        raise DesignError(f"unit points must have shape (n, {N_DESIGN}), but got {u.shape}.")
    if not np.all((u >= 0.0) & (u <= 1.0)):
        raise DesignError("unit points must lie in [0, 1].")
    if not 0.0 <= tear_probability <= 1.0:
        raise DesignError(f"tear_probability must be in [0, 1], but got {tear_probability!r}.")
    a = np.empty_like(u)
    a[:, :N_MATERIAL] = material_prior(truncate_sd).ppf(u[:, :N_MATERIAL]) / SPAN_SD
    a[:, N_MATERIAL:] = np.where(u[:, N_MATERIAL:] < tear_probability, TORN_ACTION, INTACT_ACTION)
    return np.clip(a, -1.0, 1.0)


def latin_hypercube(n: int, seed: int | np.random.SeedSequence | np.random.Generator) -> np.ndarray:
    """A seeded Latin hypercube of shape (n, 27) in [0, 1) (`scipy.stats.qmc.LatinHypercube`):
    in every column each of the n strata [k/n, (k+1)/n) holds exactly one point.
    `seed`: an int, a `numpy.random.SeedSequence` or a `Generator`."""
    from scipy.stats import qmc

    if isinstance(seed, np.random.SeedSequence):
        seed = np.random.default_rng(seed)
    return qmc.LatinHypercube(d=N_DESIGN, rng=seed).random(int(n))


def monte_carlo_actions(
    n: int,
    seed: int | np.random.SeedSequence | np.random.Generator,
    *,
    tear_probability: float = TEAR_PROBABILITY,
) -> np.ndarray:
    """The Monte Carlo study's normalized actions of shape (n, 27) (preprint 2.3.2): a seeded
    Latin hypercube over all 27 variables, mapped by `monte_carlo_from_unit` (materials from
    Table 2's normals truncated at ±3 SD, each injurable ligament torn with `tear_probability`
    independently)."""
    return monte_carlo_from_unit(latin_hypercube(n, seed), tear_probability=tear_probability)


RS_PAIR = "radioscaphoid"
TEAR_COLUMNS = tuple(f"{n}.torn" for n in INJURABLE)
FORCE_COLUMNS = tuple(f"{n}.force_n" for n in LIGAMENT_NAMES)
FRAME_COLUMNS = ("angle_deg", "rs_mean_mpa", "rs_peak_mpa", "rs_area_mm2") + FORCE_COLUMNS
"""Per-frame columns (lists, one value per frame): wrist angle (deg, flexion +), radioscaphoid
mean pressure over the contacting area and peak pressure (MPa), contact area (mm²), and the
tension of every Table 2 ligament (N)."""
_FRAMES = pa.list_(pa.float64())
SCHEMA = pa.schema(
    [("participant", pa.string()), ("sample_id", pa.int64()), ("block", pa.int64())]
    + [(n, pa.float64()) for n in NAMES]
    + [(c, pa.bool_()) for c in TEAR_COLUMNS]
    + [(c, _FRAMES) for c in FRAME_COLUMNS]
    + [("status", pa.string()), ("ok", pa.bool_()), ("excluded", pa.bool_())]
)
"""One row per run: participant, sample id (0, 1, … over the participant's blocks), block,
the 27 design variables in physical units (`design.NAMES`; injury scalars as actions), the five
tear indicators, the per-frame outputs (`FRAME_COLUMNS`; null for a failed run, whose outputs
are NaN — null keeps two logs comparable with `Table.equals`), the solver's
status, `ok` (the solver succeeded) and `excluded` (ok, but over the exclusion threshold)."""


def participant_key(participant: str) -> int:
    """A stable 32-bit key of a participant's name (CRC-32; Python's hash() is salted)."""
    return zlib.crc32(participant.encode("utf-8"))


def block_seed(seed: int, participant: str, block: int) -> np.random.SeedSequence:
    """The seed of one block of draws: the study seed, spawn key (participant key, block)."""
    if int(seed) < 0:
        raise ValueError(f"seed must be >= 0, but got {seed}")
    return np.random.SeedSequence(int(seed), spawn_key=(participant_key(participant), int(block)))


def block_actions(
    seed: int, participant: str, block: int, size: int, tear_probability: float = TEAR_PROBABILITY
) -> np.ndarray:
    """Normalized actions (size, 27) of one block: a Latin hypercube of `size` points."""
    return monte_carlo_actions(size, block_seed(seed, participant, block), tear_probability=tear_probability)


def _frames(rows: np.ndarray, missing=None) -> pa.Array:
    """Rows (n, n_frames) as a list column; rows where `missing` is True are null."""
    rows = np.ascontiguousarray(rows, dtype=np.float64)
    n, f = rows.shape
    mask = None if missing is None else pa.array(np.asarray(missing, dtype=bool))
    return pa.ListArray.from_arrays(
        pa.array(np.arange(0, n * f + 1, f, dtype=np.int32)), pa.array(rows.ravel()), mask=mask
    )


def run_chunk(
    participant: str,
    sample_ids: ArrayLike,
    blocks: ArrayLike,
    actions: ArrayLike,
    *,
    exclude_above_mpa: float = EXCLUDE_ABOVE_MPA,
    folders: Iterable[str | Path] = (),
    load_direction: str = DEFAULT_LOADS,
) -> pa.Table:
    """Simulate k runs (actions of shape (k, 27)) in one batched call; their log rows (`SCHEMA`).

    Runs wherever it is called: in this process, a local worker process or a dask worker
    (`folders`: user participant folders to register there first). load_direction: the sweep's
    load (`settings.LOAD_DIRECTIONS`).
    """
    if folders:
        for folder in folders:
            registry.ensure_folder(folder)
    actions = np.asarray(actions, dtype=np.float64)
    k = len(actions)
    idealized = task(participant, "idealized", load_direction)
    designs = design.from_actions(actions)
    infos = [e.info for e in idealized.evaluate_batch(designs)]
    angle = np.asarray(idealized.driver.angle_deg, dtype=np.float64)
    n_frames = len(angle)
    status = [str(info["status"]) for info in infos]
    ok = ~np.array([info["failed"] for info in infos], dtype=bool) & np.array([s == "ok" for s in status])

    def frames(values):
        values = np.array(list(values), dtype=np.float64).reshape(k, n_frames)
        values[~ok] = 0.0  # infos hold zeros for a failed run; the log holds null (below)
        return values

    def rs(field):
        return frames(info["contact"][RS_PAIR][field] for info in infos)

    rs_mean = rs("mean_pressure_mpa")
    excluded = ok & np.any(rs_mean > exclude_above_mpa, axis=1)
    physical = np.stack([d.vector for d in designs]) if k else np.zeros((0, len(NAMES)))
    columns = {
        "participant": [participant] * k,
        "sample_id": np.asarray(sample_ids, dtype=np.int64),
        "block": np.asarray(blocks, dtype=np.int64),
    }
    columns.update({n: physical[:, i] for i, n in enumerate(NAMES)})
    columns.update({c: actions[:, design.N_MATERIAL + i] < 0 for i, c in enumerate(TEAR_COLUMNS)})
    columns["angle_deg"] = _frames(np.tile(angle, (k, 1)))
    columns["rs_mean_mpa"] = _frames(rs_mean, ~ok)
    columns["rs_peak_mpa"] = _frames(rs("peak_pressure_mpa"), ~ok)
    columns["rs_area_mm2"] = _frames(rs("area_mm2"), ~ok)
    for lig, c in zip(LIGAMENT_NAMES, FORCE_COLUMNS):
        columns[c] = _frames(frames(info["bundle_force_n"][lig] for info in infos), ~ok)
    columns["status"] = status
    columns["ok"] = ok
    columns["excluded"] = excluded
    return pa.Table.from_pydict(columns, schema=SCHEMA)
