"""The kinematic cost of a calibration run (preprint 2.3.1.1; the one owner of it).

For the scaphoid and the lunate and each of the six DOF of `wrist_env.frames`
(Vol/Dor, Pro/Dis, Rad/Uln in mm; Flex/Ext, UlnD/RadD, Pro/Sup in degrees):

    term[b, d] = weight[d] · P75_f |error[b, f, d]| / max(range_f exp[b, f, d], floor[d])
    cost       = Σ over the 2 × 6 terms

- error: six DOF of the error transform between model and experiment at each
  frame f (`frames.error_dof`, default E = T_exp⁻¹ · T_model in the experimental
  bone's coordinate system; translations are those of the reference point,
  the bone centroid in the preprint).
- P75: the 75th percentile over frames, `numpy.percentile` default (linear
  interpolation between order statistics).
- range: max − min over frames of the experimental DOF (`frames.pose_to_dof`
  with the same reference point), floored at `RANGE_FLOOR` = 1 mm / 1° so a DOF
  that hardly moves neither divides by zero nor turns tracking noise into the
  dominant term.
- weight: the preprint weights each DOF "based on the relevance of each DOF"
  but does not state the values; the default is 1 for every DOF (`CostWeights`).

A failed simulation (any non-finite model pose) costs `FAILED_COST` = 1000, a
finite penalty far above the cost of a run that tracks at all (O(0.1–10)), but
not a hard bound: a finite run with errors of many times the motion's range
can exceed it. The reward of the environment is −cost.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, fields

import numpy as np
from numpy.typing import ArrayLike

from wrist_env.errors import InputError
from wrist_env.frames import DOF_NAMES, DOF_UNITS, error_dof_validated, pose_to_dof_validated
from wrist_env.pose_checks import validate_points, validate_poses

__all__ = [
    "COST_BONES",
    "PERCENTILE",
    "RANGE_FLOOR",
    "FAILED_COST",
    "CostWeights",
    "CostReport",
    "kinematic_cost",
]

COST_BONES = ("scaphoid", "lunate")
PERCENTILE = 75.0
RANGE_FLOOR = (1.0, 1.0, 1.0, 1.0, 1.0, 1.0)
"""Smallest range (mm, mm, mm, deg, deg, deg) a DOF is normalized by."""
FAILED_COST = 1e3
"""Cost of a failed simulation (non-finite model poses, or a non-finite cost)."""


@dataclass(frozen=True)
class CostWeights:
    """Per-DOF weights of the cost (dimensionless, >= 0, not all 0), shared by scaphoid and lunate.

    Defaults are 1: the preprint weights DOF "based on the relevance of each DOF" without values.

    Parameters
    ----------
    vol_dor, pro_dis, rad_uln : float, default 1.0
        The weights of the translations (Vol/Dor, Pro/Dis, Rad/Uln).
    flex_ext, ulnd_radd, pro_sup : float, default 1.0
        The weights of the rotations (Flex/Ext, UlnD/RadD, Pro/Sup).

    Raises
    ------
    InputError
        A weight that is not a finite number >= 0, or all weights 0.
    """

    vol_dor: float = 1.0
    pro_dis: float = 1.0
    rad_uln: float = 1.0
    flex_ext: float = 1.0
    ulnd_radd: float = 1.0
    pro_sup: float = 1.0

    def __post_init__(self):
        values = []
        for f in fields(self):
            value = getattr(self, f.name)
            try:
                value = float(value)
            except (TypeError, ValueError):
                raise InputError(f"cost weight {f.name} must be a number, but got {value!r}.") from None
            if not math.isfinite(value) or value < 0:
                raise InputError(f"cost weight {f.name} must be finite and >= 0, but got {value}.")
            object.__setattr__(self, f.name, value)
            values.append(value)
        if not any(values):
            raise InputError("cost weights must not all be 0 (the cost would be constant).")

    @classmethod
    def from_mapping(cls, mapping: Mapping) -> CostWeights:
        """Weights from {name: weight}, names from DOF_NAMES ("Flex/Ext") or fields ("flex_ext"); others stay 1."""
        field_names = [f.name for f in fields(cls)]
        names = dict(zip(field_names, field_names)) | dict(zip(DOF_NAMES, field_names))
        unknown = [k for k in mapping if k not in names]
        if unknown:
            raise InputError(f"cost weights: unknown DOF {unknown}; use {list(DOF_NAMES)} or {field_names}.")
        clash = [f for f in field_names if sum(names.get(k) == f for k in mapping) > 1]
        if clash:
            raise InputError(f"cost weights: DOF {clash} given twice (by DOF name and by field name).")
        return cls(**{names[k]: v for k, v in mapping.items()})

    def as_array(self) -> np.ndarray:
        """The weights as an array of shape (6,), in DOF_NAMES order."""
        return np.array([getattr(self, f.name) for f in fields(self)])


@dataclass(frozen=True, eq=False)
class CostReport:
    """The cost of one run and its parts.

    Arrays have shape (2, 6): bones `COST_BONES` × `DOF_NAMES`.

    Parameters
    ----------
    total : float
        The cost (dimensionless), `FAILED_COST` if failed.
    failed : bool
        True if the model poses were not finite (then terms, error_p75 and rmse are NaN).
    terms : np.ndarray, shape (2, 6)
        Weighted normalized errors, summing to total.
    error_p75 : np.ndarray, shape (2, 6)
        75th percentile over frames of ``|error|`` (mm, deg).
    experimental_range : np.ndarray, shape (2, 6)
        max − min over frames of the experimental DOF (mm, deg), before the floor.
    normalizer : np.ndarray, shape (2, 6)
        max(experimental_range, RANGE_FLOOR) (mm, deg).
    rmse : np.ndarray, shape (2, 6)
        Root mean squared error over frames (mm, deg), as the preprint's Tables 3–4.
    weights : CostWeights
        The weights used.
    """

    total: float
    failed: bool
    terms: np.ndarray
    error_p75: np.ndarray
    experimental_range: np.ndarray
    normalizer: np.ndarray
    rmse: np.ndarray
    weights: CostWeights

    def __post_init__(self):
        for name in ("terms", "error_p75", "experimental_range", "normalizer", "rmse"):
            array = np.array(getattr(self, name), dtype=np.float64)
            array.setflags(write=False)
            object.__setattr__(self, name, array)

    def to_dict(self) -> dict:
        """Plain JSON-ready dict: {"total", "failed", "weights", "units", and per array {bone: {DOF: value}}}; NaN → None."""
        out = {
            "total": float(self.total),
            "failed": bool(self.failed),
            "weights": dict(zip(DOF_NAMES, self.weights.as_array().tolist())),
            "units": dict(zip(DOF_NAMES, DOF_UNITS)),
        }
        for name in ("terms", "error_p75", "experimental_range", "normalizer", "rmse"):
            array = getattr(self, name)
            out[name] = {
                bone: {dof: _json_float(array[b, d]) for d, dof in enumerate(DOF_NAMES)}
                for b, bone in enumerate(COST_BONES)
            }
        return out


def kinematic_cost(
    model_poses: ArrayLike | Mapping[str, ArrayLike],
    experimental_poses: ArrayLike | Mapping[str, ArrayLike],
    *,
    reference_points: ArrayLike | Mapping[str, ArrayLike] | None = None,
    weights: CostWeights | Mapping | None = None,
    range_floor: ArrayLike = RANGE_FLOOR,
    expressed_in: str = "bone",
) -> CostReport:
    """The kinematic cost of model vs experimental scaphoid and lunate poses (see the module docstring).

    Parameters
    ----------
    model_poses, experimental_poses : np.ndarray, shape (2, n_frames, 4, 4), or dict of str to np.ndarray
        Bones in COST_BONES order (scaphoid, lunate), n_frames >= 2, or mappings {bone: (n_frames, 4, 4)}
        (other bones are ignored); 4×4 transforms neutral → frame, RCS, mm. Non-finite model poses → a
        failed report.
    reference_points : np.ndarray, shape (2, 3), or dict of str to np.ndarray, optional
        The tracked point of each bone, mm, RCS, neutral pose (the preprint: the centroid), or
        {bone: (3,)}; None = the RCS origin for both.
    weights : CostWeights or dict, optional
        Weights, or a mapping for `CostWeights.from_mapping`; None = all 1.
    range_floor : array_like, shape (6,), default RANGE_FLOOR
        Six floors (mm, mm, mm, deg, deg, deg) of the range normalizer, each > 0.
    expressed_in : {"bone", "rcs"}, default "bone"
        The frame the error is expressed in, see `frames.error_transform`.

    Returns
    -------
    CostReport
        The cost and its parts; `failed` if the model poses (or the cost) are not finite.

    Raises
    ------
    InputError
        Bad experimental poses, or an argument of another shape or out of range.
    """
    weights = _weights(weights)
    floor = np.asarray(range_floor, dtype=np.float64)
    if floor.shape != (6,) or not np.all(np.isfinite(floor)) or not np.all(floor > 0):
        raise InputError(
            f"range_floor must be six finite values > 0 (mm, mm, mm, deg, deg, deg), but got {range_floor!r}."
        )
    experiment = validate_poses(_by_bone(experimental_poses, "experimental poses"), "experimental poses")
    if experiment.ndim != 4 or experiment.shape[1] < 2:
        raise InputError(
            f"experimental poses: must have shape (2, n_frames >= 2, 4, 4) (scaphoid, lunate), but got {experiment.shape}."
        )
    model = _by_bone(model_poses, "model poses")
    if model.shape != experiment.shape:
        raise InputError(
            f"model poses: must have the shape of the experimental poses {experiment.shape}, but got {model.shape}."
        )
    points = _reference_points(reference_points)[:, None, :]  # (2, 1, 3): broadcast over frames

    exp_range = np.ptp(pose_to_dof_validated(experiment, points), axis=1)
    normalizer = np.maximum(exp_range, floor)
    if np.isfinite(model).all():
        model = validate_poses(model, "model poses")
        with np.errstate(over="ignore", invalid="ignore"):
            error = error_dof_validated(model, experiment, points, expressed_in=expressed_in)
            p75 = np.percentile(np.abs(error), PERCENTILE, axis=1)
            terms = weights.as_array() * p75 / normalizer
            total = float(terms.sum())
            rmse = np.sqrt(np.mean(error**2, axis=1))
        if math.isfinite(total):
            return CostReport(total, False, terms, p75, exp_range, normalizer, rmse, weights)
    nan = np.full((len(COST_BONES), len(DOF_NAMES)), np.nan)
    return CostReport(FAILED_COST, True, nan, nan, exp_range, normalizer, nan, weights)


def _by_bone(poses, name: str) -> np.ndarray:
    """Poses as a float64 array (2, ...) in COST_BONES order, from an array or a {bone: poses} mapping."""
    if isinstance(poses, Mapping):
        missing = [b for b in COST_BONES if b not in poses]
        if missing:
            raise InputError(
                f"{name}: bones {list(COST_BONES)} are required, but {missing} are missing (got {list(poses)})."
            )
        try:
            return np.stack([np.asarray(poses[b], dtype=np.float64) for b in COST_BONES])
        except ValueError as exc:
            raise InputError(
                f"{name}: scaphoid and lunate poses must be arrays of one shape (n_frames, 4, 4): {exc}"
            ) from exc
    try:
        array = np.asarray(poses, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise InputError(f"{name}: must be an array (2, n_frames, 4, 4) or a mapping by bone: {exc}") from exc
    if array.ndim != 4 or array.shape[0] != len(COST_BONES) or array.shape[2:] != (4, 4):
        raise InputError(f"{name}: must have shape (2, n_frames, 4, 4) (scaphoid, lunate), but got {array.shape}.")
    return array


def _reference_points(points) -> np.ndarray:
    if points is None:
        return np.zeros((len(COST_BONES), 3))
    if isinstance(points, Mapping):
        missing = [b for b in COST_BONES if b not in points]
        if missing:
            raise InputError(f"reference_points: bones {list(COST_BONES)} are required, but {missing} are missing.")
        return np.stack([validate_points(points[b], f"reference_points[{b!r}]") for b in COST_BONES])
    p = validate_points(points, "reference_points")
    if p.shape != (len(COST_BONES), 3):
        raise InputError(f"reference_points: must have shape (2, 3) (scaphoid, lunate; mm), but got {p.shape}.")
    return p


def _weights(weights) -> CostWeights:
    if weights is None:
        return CostWeights()
    if isinstance(weights, CostWeights):
        return weights
    if isinstance(weights, Mapping):
        return CostWeights.from_mapping(weights)
    raise InputError(f"weights must be CostWeights, a mapping by DOF name or None, but got {type(weights).__name__}.")


def _json_float(value) -> float | None:
    value = float(value)
    return value if math.isfinite(value) else None
